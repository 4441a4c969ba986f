//! Convergence curves and data profiles drawn with plotters, as SVG and PNG, with a bundled
//! font (see [`crate::plot`]) so no system font library is needed.

use super::records::{ConvergencePoint, RunRecord};
use super::report::{quantile, DataProfile};
use crate::checkpoint::write_atomic;
use czid_core::{CzError, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

const FAMILY: &str = "sans-serif";
const SIZE: (u32, u32) = (900, 600);
/// Floor of `f − f*` on the logarithmic axis.
const FLOOR: f64 = 1e-12;

use crate::plot::register_font;

fn err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> CzError + '_ {
    move |e| CzError::Io { path: path.display().to_string(), message: format!("plot: {e}") }
}

/// One band per optimizer: `(evaluations, q1, median, q3)` of `f − f*` on a grid.
type Bands = Vec<(String, Vec<(f64, f64, f64, f64)>)>;

fn bands(problem: &str, runs: &[RunRecord], curves: &[ConvergencePoint]) -> (Bands, f64) {
    let mut per: BTreeMap<(&str, u64), Vec<(usize, f64)>> = BTreeMap::new();
    for c in curves.iter().filter(|c| c.problem == problem) {
        per.entry((&c.optimizer, c.seed)).or_default().push((c.evaluations, c.best_value));
    }
    per.values_mut().for_each(|v| v.sort_by_key(|p| p.0));
    let rs: Vec<&RunRecord> = runs.iter().filter(|r| r.problem == problem).collect();
    let max_e = rs.iter().map(|r| r.evaluations).max().unwrap_or(1).max(1) as f64;
    let optimum = rs.first().map_or(0.0, |r| r.optimum);
    let mut labels: Vec<&str> = Vec::new();
    for r in &rs {
        if !labels.contains(&r.optimizer.as_str()) {
            labels.push(&r.optimizer);
        }
    }
    const GRID: usize = 200;
    let out = labels
        .iter()
        .map(|&label| {
            let seeds: Vec<&Vec<(usize, f64)>> = per.iter().filter(|((o, _), _)| *o == label).map(|(_, v)| v).collect();
            let pts = (0..=GRID)
                .filter_map(|i| {
                    let e = (1.0 + (max_e - 1.0) * i as f64 / GRID as f64).round();
                    let mut vals: Vec<f64> = seeds
                        .iter()
                        .filter_map(|c| {
                            let k = c.partition_point(|p| p.0 as f64 <= e);
                            (k > 0).then(|| (c[k - 1].1 - optimum).max(FLOOR))
                        })
                        .collect();
                    if vals.is_empty() {
                        return None;
                    }
                    vals.sort_by(f64::total_cmp);
                    Some((e, quantile(&vals, 0.25), quantile(&vals, 0.5), quantile(&vals, 0.75)))
                })
                .collect();
            (label.to_string(), pts)
        })
        .collect();
    (out, max_e)
}

fn draw_convergence<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    problem: &str,
    bands: &Bands,
    max_e: f64,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let all = bands.iter().flat_map(|(_, p)| p.iter().flat_map(|&(_, a, _, c)| [a, c]));
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    // Whole decades, so the logarithmic axis labels every power of ten in view.
    let (lo, hi) = if lo.is_finite() {
        (10f64.powf(lo.log10().floor()), 10f64.powf((hi.log10() + 1e-9).ceil()))
    } else {
        (FLOOR, 1.0)
    };
    let mut chart = ChartBuilder::on(root)
        .caption(format!("{problem}: best f − f* (median, quartile band)"), (FAMILY, 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(75)
        .build_cartesian_2d(0.0..max_e, (lo..hi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("evaluations")
        .y_desc("best f − f*")
        .y_labels(12)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    for (i, (label, pts)) in bands.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let mut poly: Vec<(f64, f64)> = pts.iter().map(|&(e, q1, _, _)| (e, q1)).collect();
        poly.extend(pts.iter().rev().map(|&(e, _, _, q3)| (e, q3)));
        chart.draw_series(std::iter::once(Polygon::new(poly, color.mix(0.2).filled())))?;
        chart
            .draw_series(LineSeries::new(pts.iter().map(|&(e, _, m, _)| (e, m)), color.stroke_width(2)))?
            .label(label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

fn draw_profiles<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    profiles: &[DataProfile],
    kappa_max: f64,
    tau: f64,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(format!("Data profiles (τ = {tau:e})"), (FAMILY, 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..kappa_max, 0.0..1.0)?;
    chart
        .configure_mesh()
        .x_desc("κ = evaluations / (n + 1)")
        .y_desc("fraction of instances solved")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .draw()?;
    for (i, p) in profiles.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        // A step function: it jumps at each instance's solving budget.
        let mut pts = vec![(0.0, 0.0)];
        for (k, &at) in p.solved_at.iter().enumerate() {
            let before = k as f64 / p.instances.max(1) as f64;
            pts.push((at, before));
            pts.push((at, (k + 1) as f64 / p.instances.max(1) as f64));
        }
        pts.push((kappa_max, p.fraction(kappa_max)));
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))?
            .label(p.optimizer.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

/// Draws `stem.svg` and `stem.png` in `dir` with `draw`, each written atomically.
fn both(
    dir: &Path,
    stem: &str,
    draw_svg: impl Fn(&DrawingArea<SVGBackend, Shift>) -> std::result::Result<(), String>,
    draw_png: impl Fn(&DrawingArea<BitMapBackend, Shift>) -> std::result::Result<(), String>,
) -> Result<()> {
    let svg_path = dir.join(format!("{stem}.svg"));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw_svg(&root).map_err(err(&svg_path))?;
    }
    write_atomic(&svg_path, svg.as_bytes())?;
    let png_path = dir.join(format!("{stem}.png"));
    let tmp = dir.join(format!(".{stem}.tmp{}.png", std::process::id()));
    {
        let root = BitMapBackend::new(&tmp, SIZE).into_drawing_area();
        draw_png(&root).map_err(err(&png_path))?;
    }
    std::fs::rename(&tmp, &png_path).map_err(err(&png_path))
}

/// File-name-safe version of a problem name.
fn stem(problem: &str) -> String {
    problem.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect()
}

/// Draws every plot of a harness output directory.
pub fn draw_all(
    dir: &Path,
    runs: &[RunRecord],
    curves: &[ConvergencePoint],
    profiles: &[DataProfile],
    tau: f64,
) -> Result<()> {
    register_font();
    let mut problems: Vec<&str> = Vec::new();
    for r in runs {
        if !problems.contains(&r.problem.as_str()) {
            problems.push(&r.problem);
        }
    }
    for problem in problems {
        let (b, max_e) = bands(problem, runs, curves);
        both(
            dir,
            &format!("convergence_{}", stem(problem)),
            |root| draw_convergence(root, problem, &b, max_e).map_err(|e| e.to_string()),
            |root| draw_convergence(root, problem, &b, max_e).map_err(|e| e.to_string()),
        )?;
    }
    let kappa_max = runs.iter().map(|r| r.evaluations as f64 / (r.dim + 1) as f64).fold(1.0, f64::max);
    both(
        dir,
        "data_profile",
        |root| draw_profiles(root, profiles, kappa_max, tau).map_err(|e| e.to_string()),
        |root| draw_profiles(root, profiles, kappa_max, tau).map_err(|e| e.to_string()),
    )
}
