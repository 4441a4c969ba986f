//! Example output curves of the forward models (CSV + SVG), no fitting involved:
//!
//! * the paper's DCB (Shi & Zhang) with the ST-CZM parameters of Table 3 (identified) and
//!   Table 2 (initial guess): load and debonded length against opening;
//! * Hartlen's DCB-01 to 30 mm opening with small and large rotations, against the test curve
//!   (bilinear law with the reported initiation toughness 0.8 N/mm and a 30 MPa strength);
//! * Hartlen's ENF-03 against its test curve (bilinear law, G_IIc = 3.5 N/mm, 60 MPa).
//!
//! `cargo run --release --example dcb_curves [output directory]` (default
//! `target/examples-output/forward_models`).

use std::path::{Path, PathBuf};

use czid_core::{columns, ForwardModel, Record};
use czid_models::dcb::Dcb;
use czid_models::enf::Enf;
use czid_models::laws::{Bilinear, StCzm};
use czid_problems::plot::{Figure, Series};

type AnyError = Box<dyn std::error::Error>;

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

/// Two numeric columns of a CSV file with a header row.
fn read_columns(path: &Path, cx: &str, cy: &str) -> Result<(Vec<f64>, Vec<f64>), AnyError> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let ix = header.iter().position(|h| h.trim() == cx).ok_or(format!("no column {cx} in {}", path.display()))?;
    let iy = header.iter().position(|h| h.trim() == cy).ok_or(format!("no column {cy} in {}", path.display()))?;
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        if let (Some(a), Some(b)) = (f.get(ix), f.get(iy)) {
            if let (Ok(a), Ok(b)) = (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
                x.push(a);
                y.push(b);
            }
        }
    }
    Ok((x, y))
}

fn col(rec: &Record, name: &str) -> Vec<f64> {
    rec.column(name).map(|c| c.to_vec()).unwrap_or_default()
}

fn main() -> Result<(), AnyError> {
    let out: PathBuf =
        std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| "target/examples-output/forward_models".into());
    std::fs::create_dir_all(&out)?;
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/hartlen-dcb-enf");

    // The paper's DCB.
    let paper = Dcb::paper();
    let t3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273)?;
    let t2 = StCzm::sawtooth(40.0, 0.0003, 0.003, 60.0, 0.000722, 0.003)?;
    let mut load = Figure::new("Paper DCB (ST-CZM)", "opening (mm)", "load (N)");
    let mut debond = Figure::new("Paper DCB (ST-CZM)", "opening (mm)", "debonded length (mm)");
    for (name, law) in [("table3", &t3), ("table2", &t2)] {
        let rec = paper.simulate(law)?;
        write_csv(&rec, &out.join(format!("paper_dcb_{name}.csv")))?;
        let x = col(&rec, columns::DISPLACEMENT);
        load = load.with(Series::line(name, x.clone(), col(&rec, columns::LOAD)));
        debond = debond.with(Series::line(name, x, col(&rec, columns::DEBONDED_LENGTH)));
    }
    load.save(&out.join("paper_dcb_load.svg"))?;
    debond.save(&out.join("paper_dcb_debonded.svg"))?;

    // Hartlen DCB-01, small and large rotations, against the test.
    let law = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0)?;
    let (tx, ty) = read_columns(&data.join("DCB-01_Toughness.csv"), "Disp", "Force")?;
    let mut fig =
        Figure::new("Hartlen DCB-01 (no fitting)", "opening (mm)", "load (N)").with(Series::points("test", tx, ty));
    for large in [false, true] {
        let mut d = Dcb::hartlen_dcb01();
        d.effects.large_rotation = large;
        let rec = d.simulate(&law)?;
        let name = if large { "large_rotation" } else { "small_rotation" };
        write_csv(&rec, &out.join(format!("hartlen_dcb01_{name}.csv")))?;
        fig = fig.with(Series::line(name, col(&rec, columns::DISPLACEMENT), col(&rec, columns::LOAD)));
    }
    fig.save(&out.join("hartlen_dcb01.svg"))?;

    // Hartlen ENF-03 against the test.
    let enf = Enf::hartlen_enf03();
    let law = Bilinear::bk(1e5, 40.0, 60.0, 1.0, 3.5, 2.0)?;
    let rec = enf.simulate(&law)?;
    write_csv(&rec, &out.join("hartlen_enf03.csv"))?;
    let (tx, ty) = read_columns(&data.join("ENF-03.csv"), "FrameDisp_(mm)", "Load_(N)")?;
    Figure::new("Hartlen ENF-03 (no fitting)", "load-point deflection (mm)", "load (N)")
        .with(Series::points("test", tx, ty))
        .with(Series::line("model", col(&rec, columns::DISPLACEMENT), col(&rec, columns::LOAD)))
        .save(&out.join("hartlen_enf03.svg"))?;
    println!("curves written to {}", out.display());
    Ok(())
}
