//! The diagnosis written out: `gap.json`, `report.md` and plots (residuals with the regimes
//! marked, fits with and without the best candidate, candidate scores).

use crate::diagnose::run::Diagnosis;
use crate::output::OutputDir;
use crate::plot::{Figure, Series};
use czid_core::{columns, CzError, Result};
use std::fmt::Write;

/// Writes `gap.json`, `report.md` and the plots into `out`; returns the files written.
pub fn write(d: &Diagnosis, out: &OutputDir) -> Result<Vec<String>> {
    let json = serde_json::to_string_pretty(d).map_err(|e| CzError::config("gap.json", e.to_string()))?;
    let mut files = vec![out.write("gap.json", &json)?.display().to_string()];
    let plots = plots(d, out)?;
    files.push(out.write("report.md", &markdown(d, &plots))?.display().to_string());
    files.extend(plots);
    Ok(files)
}

fn plots(d: &Diagnosis, out: &OutputDir) -> Result<Vec<String>> {
    let Some(gauge) = &d.gauge else { return Ok(Vec::new()) };
    let mut files = Vec::new();
    for (b, range) in gauge.blocks.iter().zip(gauge.ranges()) {
        let (what, unit) = (b.term.noun(), b.term.unit());
        let r: Vec<f64> = d.base_residuals[range].iter().map(|v| v * b.sigma).collect();
        let mut fig = Figure::new(
            &format!("{}: {what} residual (test − model)", b.experiment),
            "displacement (mm)",
            &format!("test − model ({unit})"),
        )
        .with(Series::points("base fit", b.x.clone(), r))
        .with(Series::dashed("+2σ noise", vec![b.x[0], b.x[b.x.len() - 1]], vec![2.0 * b.sigma; 2]))
        .with(Series::dashed("−2σ noise", vec![b.x[0], b.x[b.x.len() - 1]], vec![-2.0 * b.sigma; 2]));
        for g in d.regimes.iter().filter(|g| g.experiment == b.experiment).skip(1) {
            fig = fig.with_vline(&g.name, g.from);
        }
        let name = format!("residual-{}-{}.png", b.experiment, b.term.symbol());
        fig.save(&out.file(&name))?;
        files.push(name);

        let Some(column) = b.term.column() else { continue };
        let accounted = d.model_form.applied();
        let mut fit =
            Figure::new(&format!("{}: {what}", b.experiment), "displacement (mm)", &format!("{what} ({unit})")).with(
                Series::points(if accounted { "test, model form accounted" } else { "test" }, b.x.clone(), b.y.clone()),
            );
        if let (true, Some(m)) = (accounted, &d.measured) {
            if let Some(mb) = m.blocks.iter().find(|mb| mb.experiment == b.experiment && mb.term == b.term) {
                fit = fit.with(Series::points("test as measured", mb.x.clone(), mb.y.clone()));
            }
        }
        if let Some(rec) = d.base_records.get(&b.experiment) {
            let c = rec.curve(columns::DISPLACEMENT, column)?;
            fit = fit.with(Series::line("base fit", c.x().to_vec(), c.y().to_vec()));
        }
        if let Some((name, recs)) = &d.best_records {
            if let Some(rec) = recs.get(&b.experiment) {
                let c = rec.curve(columns::DISPLACEMENT, column)?;
                fit = fit.with(Series::line(&format!("with {name}"), c.x().to_vec(), c.y().to_vec()));
            }
        }
        for g in d.regimes.iter().filter(|g| g.experiment == b.experiment).skip(1) {
            fit = fit.with_vline(&g.name, g.from);
        }
        let name = format!("fit-{}-{}.png", b.experiment, b.term.symbol());
        fit.save(&out.file(&name))?;
        files.push(name);
    }
    let scored: Vec<(usize, &str, f64)> = d
        .candidates
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.score.as_ref().map(|s| (i, c.name.as_str(), s.statistic.max(1e-3))))
        .collect();
    if !scored.is_empty() {
        let mut fig =
            Figure::new("candidate scores (χ² units; dashed: significance threshold)", "rank", "score S_e").log_y();
        for (i, name, s) in &scored {
            let x = (*i + 1) as f64;
            fig = fig.with(Series::line(name, vec![x, x], vec![1e-3, *s]));
        }
        // The χ²₁ value at the family-wise level, for reference.
        let threshold = threshold(scored.len());
        fig = fig.with(Series::dashed("threshold (1 dof)", vec![0.5, scored.len() as f64 + 0.5], vec![threshold; 2]));
        fig.save(&out.file("scores.png"))?;
        files.push("scores.png".into());
    }
    Ok(files)
}

/// χ²₁ quantile at the family-wise level over `m` candidates (bisection on the tail).
fn threshold(m: usize) -> f64 {
    let target = crate::diagnose::score::SIGNIFICANCE / m.max(1) as f64;
    let (mut lo, mut hi) = (0.0, 200.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if crate::diagnose::stats::chi2_survival(mid, 1.0) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |v| format!("{v:.digits$}"))
}

/// The report in Markdown: verdict, noise, base fit, where, which, how far, plots.
pub fn markdown(d: &Diagnosis, plots: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Sim-to-real gap: {}\n", d.problem);
    let _ = writeln!(s, "**Verdict.** {}\n", d.verdict);
    let _ = writeln!(s, "{} readings; diagnosis took {:.1} s.\n", d.readings, d.wall_seconds);
    outcome_section(&mut s, d);
    noise_section(&mut s, d);
    model_form_section(&mut s, d);
    base_section(&mut s, d);
    where_section(&mut s, d);
    which_section(&mut s, d);
    how_far_section(&mut s, d);
    if !plots.is_empty() {
        let _ = writeln!(s, "\n## Plots\n");
        for p in plots {
            let _ = writeln!(s, "![{p}]({p})");
        }
    }
    s
}

/// The machine-readable verdict, as a table.
fn outcome_section(s: &mut String, d: &Diagnosis) {
    let o = &d.outcome;
    let kind = serde_json::to_value(o.kind).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default();
    let _ = writeln!(s, "| kind | cause | shrinkage | transfer | confusable with | more missing | provisional |\n|---|---|---|---|---|---|---|");
    let _ = writeln!(
        s,
        "| {kind} | {} | {} | {} | {} | {} | {} |\n",
        o.cause.clone().unwrap_or_else(|| "–".into()),
        o.shrinkage.map_or("–".into(), |v| format!("{:.0}%", 100.0 * v)),
        o.transfer_shrinkage.map_or("–".into(), |v| format!("{:.0}%", 100.0 * v)),
        if o.confusable_with.is_empty() { "–".into() } else { o.confusable_with.join(", ") },
        if o.more_missing { "yes" } else { "no" },
        if o.provisional { "yes" } else { "no" }
    );
    for r in &o.reasons {
        let _ = writeln!(s, "* {r}");
    }
}

/// The model-form floor.
fn model_form_section(s: &mut String, d: &Diagnosis) {
    let f = &d.model_form;
    let _ = writeln!(s, "\n## Model form\n");
    match &f.note {
        Some(note) => {
            let _ = writeln!(s, "Not accounted for: {note}. Candidates are judged against the noise alone.");
        }
        None => {
            let refs: Vec<String> = f.reference.iter().map(|(e, m)| format!("{e}: `{m}`")).collect();
            let _ = writeln!(
                s,
                "The base fit run through the reference model ({}) differs from it by {:.2} noise units RMS ({:.2} at most): the misfit the base model's form leaves on any test. With that shift accounted for, the base fit's χ² goes from {:.1} to {:.1}; the candidates below are judged on the accounted data.",
                refs.join(", "),
                f.shift_rms,
                f.shift_max,
                f.chi2_as_measured,
                f.chi2_accounted
            );
        }
    }
}

/// Noise per response.
fn noise_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "## Noise\n\n| experiment | response | σ | estimated from the data |\n|---|---|---|---|");
    for n in &d.noise {
        let _ = writeln!(s, "| {} | {} | {:.4} {} | {} |", n.experiment, n.term, n.sigma, n.unit, n.estimated);
    }
}

/// The base fit and what the data say about its parameters.
fn base_section(s: &mut String, d: &Diagnosis) {
    let b = &d.base;
    let _ = writeln!(
        s,
        "\n## Base fit\n\nχ² = {:.1} in noise units, χ²/dof = {:.2} (p = {:.2e}): {}.\n",
        b.chi2,
        b.reduced_chi2,
        b.p_value,
        if b.at_noise_level { "at the noise level" } else { "above the noise level" }
    );
    let _ = writeln!(s, "| parameter | value | standard error | sensitivity | verdict |\n|---|---|---|---|---|");
    for q in &b.parameters {
        let _ = writeln!(
            s,
            "| `{}` | {:.5e} {} | {} | {:.3e} | {} |",
            q.path,
            q.value,
            q.unit,
            q.standard_error.map_or("–".into(), |v| format!("{v:.3e}")),
            q.sensitivity,
            q.verdict
        );
    }
    let id = &d.identifiability;
    let _ = writeln!(
        s,
        "\nSingular values: {}; collinearity index {:.2}.\n",
        id.singular_values.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(", "),
        id.collinearity_index
    );
}

/// The regimes and the misfit in each.
fn where_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "## Where\n\n| experiment | regime | displacements (mm) |\n|---|---|---|");
    for g in &d.regimes {
        let _ = writeln!(s, "| {} | {} | {:.3} – {:.3} |", g.experiment, g.name, g.from, g.to);
    }
    let _ = writeln!(
        s,
        "\n| experiment | regime | response | readings | mean test − model | rms | rms/σ | share of misfit | sign |\n|---|---|---|---|---|---|---|---|---|"
    );
    for m in &d.misfit {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:+.3} {} | {:.3} {} | {:.1} | {:.0}% | {} |",
            m.experiment,
            m.regime,
            m.term,
            m.readings,
            m.mean,
            m.unit,
            m.rms,
            m.unit,
            m.rms_over_noise,
            100.0 * m.share,
            m.sign
        );
    }
}

/// The candidates' scores at the base fit.
fn which_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n## Which: candidate effects at the base fit\n\n| candidate | score | dof | p | significant | explained (1st order) | angle to fitted (°) | absorbed by | predicted size |\n|---|---|---|---|---|---|---|---|---|"
    );
    for c in &d.candidates {
        match &c.score {
            Some(sc) => {
                let size: Vec<String> = sc.predicted.iter().map(|(n, v, u)| format!("{n} = {v:.3e} {u}")).collect();
                let _ = writeln!(
                    s,
                    "| {} | {:.1} | {} | {:.1e} | {} | {:.0}% | {:.1} | {} | {} |",
                    c.name,
                    sc.statistic,
                    sc.dof,
                    sc.p_value,
                    if sc.significant { "yes" } else { "no" },
                    100.0 * sc.explained,
                    sc.angle_deg,
                    match (&sc.absorbed_by, sc.absorbed_shift) {
                        (Some(p), Some(v)) => format!("`{p}` ({v:+.3e})"),
                        _ => "–".into(),
                    },
                    size.join("; ")
                );
            }
            None => {
                let _ = writeln!(s, "| {} | – | | | | | | | {} |", c.name, c.error.clone().unwrap_or_default());
            }
        }
    }
    for (name, why) in &d.skipped {
        let _ = writeln!(s, "\n`{name}`: {why}.");
    }
    if !d.base.at_bound.is_empty() {
        let _ = writeln!(s, "\nAt a bound after the restarts: {}.", d.base.at_bound.join(", "));
    }
    if !d.confusable.is_empty() {
        let _ = writeln!(s, "\nConfusable pairs (cosine of their sensitivities beyond the fitted parameters):\n");
        for c in &d.confusable {
            let _ = writeln!(s, "* {} and {}: {:.3}", c.a, c.b, c.cos);
        }
    }
}

/// The refits, their transfer and their shrinkage per regime.
fn how_far_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n## How far: refits with the effect on\n\n| candidate | χ² | shrinkage | ΔAIC | ΔBIC | effect | transfer |\n|---|---|---|---|---|---|---|"
    );
    for c in d.candidates.iter().filter(|c| c.refit.is_some()) {
        let r = c.refit.as_ref().expect("filtered");
        let effect: Vec<String> = r.effect.iter().map(|v| format!("{} = {:.3e} {}", v.name, v.value, v.unit)).collect();
        let transfer: Vec<String> = c
            .transfer
            .iter()
            .map(|t| match t.shrinkage {
                Some(sh) => {
                    format!("{}: {:.0}% (χ² {:.1} → {})", t.withheld, 100.0 * sh, t.base_chi2, opt(t.effect_chi2, 1))
                }
                None => format!("{}: {}", t.withheld, t.note.clone().unwrap_or_default()),
            })
            .collect();
        let _ = writeln!(
            s,
            "| {}{} | {:.1} | {:.0}% | {:.1} | {:.1} | {} | {} |",
            c.name,
            if c.on_request { " (refitted on request, not judged)" } else { "" },
            r.chi2,
            100.0 * r.shrinkage,
            r.delta_aic,
            r.delta_bic,
            effect.join("; "),
            transfer.join("; ")
        );
    }
    for c in d.candidates.iter().filter(|c| c.refit.is_some()) {
        let r = c.refit.as_ref().expect("filtered");
        let _ = writeln!(s, "\nShrinkage per regime with {}:\n\n| experiment | regime | χ² before | after | shrinkage |\n|---|---|---|---|---|", c.name);
        for g in &r.by_regime {
            let _ = writeln!(
                s,
                "| {} | {} | {:.1} | {:.1} | {:.0}% |",
                g.experiment,
                g.regime,
                g.before,
                g.after,
                100.0 * g.shrinkage
            );
        }
    }
}
