//! The paper's FRP-strengthened beam run to complete debonding with the Table 8 law, and its
//! plots: load against mid-span deflection, debonded length and process zone against deflection,
//! and the plate's strain along the half plate at several stages.
//!
//! `cargo run --release --example frp_beam_plots [config] [output directory]` (defaults
//! `examples/frp-beam/beam.toml` and `target/examples-output/frp_beam`). Writes `record.csv`,
//! `frp_beam_load.png`, `frp_beam_debonding.png` and `frp_beam_strain.png`, and prints a summary.

use std::path::{Path, PathBuf};

use czid_core::{columns, Record};
use czid_models::frp::beam::{BeamRun, FrpBeam};
use czid_models::laws::StCzm;
use czid_optimizers::plot::{Figure, Series};
use serde::Deserialize;

type AnyError = Box<dyn std::error::Error>;

/// The configuration file: the interface law and the beam.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Config {
    law: StCzm,
    model: FrpBeam,
}

/// The model file's law and beam: its `type` keys name them (`st_czm`, `frp_beam`), the rest are
/// their fields.
fn read_config(text: &str) -> Result<Config, AnyError> {
    let mut table: toml::Table = toml::from_str(text)?;
    for (section, kind) in [("law", "st_czm"), ("model", "frp_beam")] {
        let t = table.get_mut(section).and_then(|v| v.as_table_mut()).ok_or(format!("no [{section}] table"))?;
        match t.remove("type") {
            Some(toml::Value::String(k)) if k == kind => {}
            other => return Err(format!("[{section}] must have type = \"{kind}\" (found {other:?})").into()),
        }
    }
    Ok(table.try_into()?)
}

fn col(rec: &Record, name: &str) -> Vec<f64> {
    rec.column(name).map(|c| c.to_vec()).unwrap_or_default()
}

fn write_csv(rec: &Record, path: &Path) -> Result<(), AnyError> {
    let names: Vec<String> = rec.columns().iter().map(|c| format!("{} [{}]", c.name, c.unit)).collect();
    let mut out = names.join(",") + "\n";
    for i in 0..rec.rows() {
        let row: Vec<String> = rec.columns().iter().map(|c| format!("{:.9e}", c.values[i])).collect();
        out += &(row.join(",") + "\n");
    }
    std::fs::write(path, out)?;
    Ok(())
}

/// Rows of the stages whose plate strain is drawn: before debonding, at its onset, at the peak
/// load, half-way through the propagation, just before and after complete debonding.
fn stages(run: &BeamRun, half_plate: f64) -> Vec<(String, usize)> {
    let rec = &run.record;
    let (p, l, d) = (col(rec, columns::LOAD), col(rec, columns::DEBONDED_LENGTH), col(rec, columns::DISPLACEMENT));
    let last = rec.rows() - 1;
    let onset = run.debonding_start.map_or(last / 2, |s| s.row);
    let peak = (0..=last).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(last);
    let half = (0..=last).find(|&i| l[i] >= 0.5 * half_plate).unwrap_or(last);
    let before = last.saturating_sub(2);
    let mut rows = vec![onset / 2, onset, peak, half, before, last];
    rows.dedup();
    rows.into_iter()
        .map(|i| (format!("w = {:.1} mm, P = {:.0} kN, debonded {:.0} mm", d[i], p[i] / 1e3, l[i]), i))
        .collect()
}

fn main() -> Result<(), AnyError> {
    let mut args = std::env::args().skip(1);
    let config = args.next().map(PathBuf::from).unwrap_or_else(|| "examples/frp-beam/beam.toml".into());
    let out = args.next().map(PathBuf::from).unwrap_or_else(|| "target/examples-output/frp_beam".into());
    std::fs::create_dir_all(&out)?;
    let text = std::fs::read_to_string(&config).map_err(|e| format!("{}: {e}", config.display()))?;
    let cfg = read_config(&text).map_err(|e| format!("{}: {e}", config.display()))?;
    let beam = cfg.model;
    let started = std::time::Instant::now();
    let run = beam.run(&cfg.law, true).map_err(|f| format!("the run stopped: {}", f.error))?;
    let seconds = started.elapsed().as_secs_f64();
    let rec = &run.record;
    write_csv(rec, &out.join("record.csv"))?;

    let kn = |v: Vec<f64>| v.into_iter().map(|x| x / 1e3).collect::<Vec<f64>>();
    let (w, p) = (col(rec, columns::DISPLACEMENT), col(rec, columns::LOAD));
    let (l, z) = (col(rec, columns::DEBONDED_LENGTH), col(rec, columns::PROCESS_ZONE_LENGTH));
    let last = rec.rows() - 1;
    let peak = (0..=last).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(last);
    let mut load = Figure::new("FRP-plated beam, Table 8 law: load", "mid-span deflection (mm)", "total load P (kN)")
        .with(Series::line("frp_beam", w.clone(), kn(p.clone())));
    if let Some(s) = run.debonding_start {
        load = load.with_vline("first interface point fails", w[s.row]);
    }
    load = load.with_vline("peak load", w[peak]);
    load.save(&out.join("frp_beam_load.png"))?;
    Figure::new("FRP-plated beam: debonding", "mid-span deflection (mm)", "length along the half plate (mm)")
        .with(Series::line("debonded (D = 1)", w.clone(), l.clone()))
        .with(Series::dashed("process zone (0 < D < 1)", w.clone(), z.clone()))
        .save(&out.join("frp_beam_debonding.png"))?;
    let half_plate = 0.5 * beam.plate_length;
    let mut strain = Figure::new("FRP-plated beam: plate strain", "distance from mid-span (mm)", "plate strain (‰)");
    for (label, row) in stages(&run, half_plate) {
        let pr = &run.profiles[row];
        strain = strain.with(Series::line(&label, pr.x.clone(), pr.plate_strain.iter().map(|e| 1e3 * e).collect()));
    }
    strain.save(&out.join("frp_beam_strain.png"))?;

    let start = run.debonding_start.ok_or("no interface point failed")?;
    println!("run: {:.3} s, {} steps, end {:?}", seconds, run.stats.steps, run.end);
    println!(
        "first failure: P = {:.1} kN at w = {:.2} mm, points {:.0}-{:.0} mm from mid-span",
        p[start.row] / 1e3,
        w[start.row],
        start.x.0,
        start.x.1
    );
    println!("peak (debonding) load: P = {:.1} kN at w = {:.2} mm, debonded {:.0} mm", p[peak] / 1e3, w[peak], l[peak]);
    println!("end: P = {:.1} kN at w = {:.2} mm, debonded {:.0} mm", p[last] / 1e3, w[last], l[last]);
    println!("outputs in {}", out.display());
    Ok(())
}
