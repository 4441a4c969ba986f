//! Experimental data: a test's curves read from a CSV file, checked, and converted to N and mm.
//!
//! Every problem with the file is reported with the file name, the row (1-based, counting the
//! header as row 1, as a spreadsheet shows it) and the column, and what is expected instead.

use czid_core::{Curve, CzError, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Unit of a length column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LengthUnit {
    /// Millimetres (czid's unit).
    #[default]
    #[serde(rename = "mm")]
    Millimetre,
    /// Metres.
    #[serde(rename = "m")]
    Metre,
    /// Inches.
    #[serde(rename = "in")]
    Inch,
}

impl LengthUnit {
    /// Factor to millimetres.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1.0,
            LengthUnit::Metre => 1000.0,
            LengthUnit::Inch => 25.4,
        }
    }
}

/// Unit of a force column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ForceUnit {
    /// Newtons (czid's unit).
    #[default]
    N,
    /// Kilonewtons.
    #[serde(rename = "kN")]
    KiloNewton,
    /// Pounds-force.
    #[serde(rename = "lbf")]
    PoundForce,
}

impl ForceUnit {
    /// Factor to newtons.
    pub fn to_newton(self) -> f64 {
        match self {
            ForceUnit::N => 1.0,
            ForceUnit::KiloNewton => 1000.0,
            ForceUnit::PoundForce => 4.448_221_615_260_5,
        }
    }
}

/// What a test's `load` column holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ordinate {
    /// The load (the record's `load`, N).
    #[default]
    Load,
    /// The mid-span moment of a beam in four-point bending (the record's `midspan_moment`,
    /// `P/2 ×` shear span for a total load `P`), in `moment_unit`: the paper's moment–deflection
    /// curve.
    MidspanMoment,
}

impl Ordinate {
    /// The record column it is compared with.
    pub fn column(self) -> &'static str {
        match self {
            Ordinate::Load => czid_core::columns::LOAD,
            Ordinate::MidspanMoment => czid_models::frp::beam::beam_columns::MIDSPAN_MOMENT,
        }
    }

    /// Its unit once read (N or N·mm).
    pub fn unit(self) -> &'static str {
        match self {
            Ordinate::Load => "N",
            Ordinate::MidspanMoment => "N·mm",
        }
    }
}

/// Unit of a moment column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MomentUnit {
    /// Newton-millimetres (czid's unit).
    #[default]
    #[serde(rename = "N·mm", alias = "N.mm", alias = "Nmm")]
    NewtonMillimetre,
    /// Newton-metres.
    #[serde(rename = "N·m", alias = "N.m", alias = "Nm")]
    NewtonMetre,
    /// Kilonewton-metres.
    #[serde(rename = "kN·m", alias = "kN.m", alias = "kNm")]
    KiloNewtonMetre,
}

impl MomentUnit {
    /// Factor to N·mm.
    pub fn to_newton_millimetre(self) -> f64 {
        match self {
            MomentUnit::NewtonMillimetre => 1.0,
            MomentUnit::NewtonMetre => 1e3,
            MomentUnit::KiloNewtonMetre => 1e6,
        }
    }
}

/// What a crack column holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrackMeasure {
    /// Crack length from the load line; its first value is a0, so debonded length = value − a0.
    #[default]
    CrackLength,
    /// Debonded length (crack growth) directly.
    DebondedLength,
}

/// Where a test's data is and how to read it (the `[experiment]` table of a problem file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentSpec {
    /// CSV file, relative to the problem file.
    pub file: PathBuf,
    /// Column with the control displacement (e.g. load-line opening).
    pub displacement: String,
    /// Column with the load (or, with `ordinate = "midspan_moment"`, the mid-span moment).
    pub load: String,
    /// What the `load` column holds: the load (default) or the mid-span moment.
    #[serde(default)]
    pub ordinate: Ordinate,
    /// Unit of a moment column (`N·mm`, `N·m`, `kN·m`; default N·mm).
    #[serde(default)]
    pub moment_unit: MomentUnit,
    /// Column with the crack or debonded length, if measured.
    #[serde(default)]
    pub crack: Option<String>,
    /// What the crack column holds.
    #[serde(default)]
    pub crack_measure: CrackMeasure,
    /// Unit of the displacement and crack columns.
    #[serde(default)]
    pub length_unit: LengthUnit,
    /// Unit of the load column.
    #[serde(default)]
    pub force_unit: ForceUnit,
    /// Only use rows with displacement in `[min, max]` (mm, after unit conversion).
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    /// Drop rows whose displacement does not exceed every earlier one (machine relaxation at the
    /// end of a test, noise in a seating toe) instead of reporting them as an error.
    #[serde(default)]
    pub drop_non_increasing: bool,
    /// Drop rows with a missing or non-finite reading (`NaN`, `inf`, an empty cell) in a column
    /// that is read, instead of reporting them as an error (some test machines write such rows
    /// when a channel drops out).
    #[serde(default)]
    pub drop_non_finite: bool,
    /// Compensate a seating toe as ASTM D790, D5528 and D7905 do: fit a line to the rising branch
    /// where the load lies between these fractions of the peak load (e.g. `[0.2, 0.5]`), move the
    /// displacement zero to where that line meets zero load, and drop the readings before the
    /// branch (the toe, where the fixture seats). The shift is reported with the dropped rows.
    #[serde(default)]
    pub toe_compensation: Option<[f64; 2]>,
    /// Standard deviation of the load readings (N; N·mm with `ordinate = "midspan_moment"`), if
    /// known (a load cell's stated accuracy). `weights = "noise"` uses it; without it the noise is
    /// estimated from the readings themselves.
    #[serde(default)]
    pub load_noise: Option<f64>,
    /// Standard deviation of the crack or debonded-length readings (mm), if known; as `load_noise`.
    #[serde(default)]
    pub length_noise: Option<f64>,
}

/// The stated standard deviations of a test's readings (`load_noise`, `length_noise` of its data
/// table), for weighting the objective by the noise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReadingNoise {
    /// Of the load (N, or N·mm for a moment).
    pub load: Option<f64>,
    /// Of the debonded length (mm).
    pub debonded_length: Option<f64>,
}

/// Rows of a data file that reading left out, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DroppedRows {
    /// With a missing or non-finite reading (`drop_non_finite`).
    pub non_finite: usize,
    /// Whose displacement does not increase (`drop_non_increasing`).
    pub non_increasing: usize,
    /// Outside the displacement `range`.
    pub out_of_range: usize,
    /// Before the linear branch of a compensated seating toe (`toe_compensation`).
    pub toe: usize,
    /// Where the compensated toe's linear branch meets zero load (mm, in the file's zero): every
    /// kept displacement was moved down by it. Zero without `toe_compensation`.
    pub toe_zero: f64,
}

impl DroppedRows {
    /// What was dropped, in words (`None`: nothing).
    pub fn describe(&self) -> Option<String> {
        let mut parts: Vec<String> = [
            (self.non_finite, "with a missing or non-finite reading"),
            (self.non_increasing, "whose displacement does not increase"),
            (self.out_of_range, "outside the displacement range"),
            (self.toe, "in the seating toe"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, why)| format!("{n} {why}"))
        .collect();
        if self.toe_zero != 0.0 {
            parts.push(format!("displacement zero moved by {:.4} mm (toe compensation)", self.toe_zero));
        }
        (!parts.is_empty()).then(|| format!("rows dropped: {}", parts.join(", ")))
    }
}

/// A test's curves in N and mm.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// Name (the file stem unless given).
    pub name: String,
    /// Load (N) against displacement (mm).
    pub load: Curve,
    /// Debonded length (mm) against displacement (mm), when measured.
    pub debonded_length: Option<Curve>,
    /// First value of a crack-length column (the initial crack length a0, mm), when given.
    pub initial_crack: Option<f64>,
    /// Rows of the file left out, by reason.
    pub dropped: DroppedRows,
    /// Measured events (`[[experiment.event]]` of a problem file; none from the data file).
    pub events: Vec<crate::event::MeasuredEvent>,
    /// What `load` holds (the load, or the mid-span moment in N·mm).
    pub ordinate: Ordinate,
    /// The readings' stated noise, where the data table gives it.
    pub noise: ReadingNoise,
}

impl ExperimentSpec {
    /// Reads and checks the data; `base` is the folder relative paths start from.
    pub fn load(&self, base: &Path) -> Result<Experiment> {
        let path = base.join(&self.file);
        let shown = path.display().to_string();
        for (key, v) in [("load_noise", self.load_noise), ("length_noise", self.length_noise)] {
            if let Some(v) = v {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(CzError::invalid(
                        format!("data of {shown}"),
                        key,
                        v,
                        "must be a positive standard deviation (N or mm); leave it out to estimate the noise from the readings",
                    ));
                }
            }
        }
        let text = std::fs::read_to_string(&path).map_err(|e| CzError::Io {
            path: shown.clone(),
            message: format!("{e} (paths in a problem file are relative to the problem file)"),
        })?;
        let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| CzError::data(&shown, format!("cannot read the header row: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        let find = |key: &str, name: &str| -> Result<usize> {
            header.iter().position(|h| h == name).ok_or_else(|| {
                CzError::data(
                    &shown,
                    format!("no column `{name}` (asked for by `{key}`); the columns are: {}", header.join(", ")),
                )
            })
        };
        let ix = find("displacement", &self.displacement)?;
        let iy = find("load", &self.load)?;
        let ic = self.crack.as_deref().map(|c| find("crack", c)).transpose()?;

        let lu = self.length_unit.to_mm();
        let fu = match self.ordinate {
            Ordinate::Load => self.force_unit.to_newton(),
            Ordinate::MidspanMoment => self.moment_unit.to_newton_millimetre(),
        };
        let mut rows: Vec<Row> = Vec::new();
        let mut dropped = DroppedRows::default();
        for (i, record) in reader.records().enumerate() {
            let row = i + 2;
            let record = record.map_err(|e| CzError::data(format!("{shown}, row {row}"), e.to_string()))?;
            // A value is read, converted to N or mm, and checked after the conversion: a huge
            // reading in metres or kilonewtons can overflow to infinity on the way.
            let cell = |col: usize, factor: f64| -> Result<f64> {
                let raw = record.get(col).unwrap_or("");
                let at = || format!("{shown}, row {row}, column `{}`", header[col]);
                let v: f64 = raw.parse().map_err(|_| CzError::data(at(), format!("`{raw}` is not a number")))?;
                if !v.is_finite() {
                    return Err(CzError::data(at(), format!("`{raw}` is not a finite number")));
                }
                let converted = v * factor;
                if !converted.is_finite() {
                    return Err(CzError::data(at(), format!("`{raw}` overflows when converted to N or mm")));
                }
                Ok(converted)
            };
            let read = || -> Result<Row> {
                Ok(Row { line: row, x: cell(ix, lu)?, y: cell(iy, fu)?, crack: ic.map(|c| cell(c, lu)).transpose()? })
            };
            match read() {
                Ok(r) => rows.push(r),
                Err(_) if self.drop_non_finite && missing_or_non_finite(&record, &[Some(ix), Some(iy), ic]) => {
                    dropped.non_finite += 1;
                }
                Err(e) => {
                    return Err(match e {
                        // The cell's own error already says where; add the way out.
                        CzError::Data { location, message }
                            if missing_or_non_finite(&record, &[Some(ix), Some(iy), ic]) =>
                        {
                            CzError::data(
                                location,
                                format!("{message}; set `drop_non_finite = true` to drop such rows"),
                            )
                        }
                        e => e,
                    });
                }
            }
        }
        if rows.is_empty() {
            return Err(CzError::data(&shown, "the file has a header but no data rows"));
        }
        let initial_crack = match self.crack_measure {
            CrackMeasure::CrackLength => rows[0].crack,
            CrackMeasure::DebondedLength => None,
        };

        // Rows keep their line numbers so errors point at the file, not at a filtered copy.
        let mut kept = rows;
        if let Some([lo, hi]) = self.range {
            if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
                return Err(CzError::config(
                    format!("experiment `{}`", self.file.display()),
                    format!("range [{lo}, {hi}] must have min < max"),
                ));
            }
            let before = kept.len();
            kept.retain(|r| r.x >= lo && r.x <= hi);
            dropped.out_of_range = before - kept.len();
            if kept.is_empty() {
                return Err(CzError::data(&shown, format!("no rows with displacement in the range [{lo}, {hi}] mm")));
            }
        }
        let mut reach = f64::NEG_INFINITY;
        let mut monotone = Vec::with_capacity(kept.len());
        for r in kept {
            if r.x > reach {
                reach = r.x;
                monotone.push(r);
            } else if self.drop_non_increasing {
                dropped.non_increasing += 1;
            } else {
                return Err(CzError::data(
                    format!("{shown}, row {}, column `{}`", r.line, self.displacement),
                    format!(
                        "displacement {} mm does not increase (an earlier row reached {reach} mm); \
                         set `drop_non_increasing = true` to drop such rows, or limit `range`",
                        r.x
                    ),
                ));
            }
        }
        if let Some(band) = self.toe_compensation {
            let (toe, zero) = compensate_toe(&mut monotone, band, &shown)?;
            dropped.toe = toe;
            dropped.toe_zero = zero;
        }
        // One reading is no curve: nothing could be fitted to it, and every parameter would look
        // determined by it.
        if monotone.len() < 2 {
            return Err(CzError::data(
                &shown,
                format!(
                    "{} usable reading(s) after the range and dropped rows; a test curve needs at least 2",
                    monotone.len()
                ),
            ));
        }
        let x: Vec<f64> = monotone.iter().map(|r| r.x).collect();
        // A curve the checks above let through can still be refused (a crack length minus its
        // first value can overflow): the error then names the file.
        let in_file = |e: CzError| CzError::data(&shown, e.to_string());
        let load = Curve::new(x.clone(), monotone.iter().map(|r| r.y).collect()).map_err(in_file)?;
        let debonded_length = match ic {
            None => None,
            Some(_) => {
                let offset = initial_crack.unwrap_or(0.0);
                Some(
                    Curve::new(x, monotone.iter().map(|r| r.crack.unwrap_or(0.0) - offset).collect())
                        .map_err(in_file)?,
                )
            }
        };
        let name = self.file.file_stem().map_or_else(|| shown.clone(), |s| s.to_string_lossy().into_owned());
        Ok(Experiment {
            name,
            load,
            debonded_length,
            initial_crack,
            dropped,
            events: Vec::new(),
            ordinate: self.ordinate,
            noise: ReadingNoise { load: self.load_noise, debonded_length: self.length_noise },
        })
    }
}

/// Toe compensation (ASTM D790, D5528, D7905): the line through the rising branch with loads in
/// `band` × the peak load, `P = k (δ − δ₀)`, moves the displacement zero to `δ₀`; the readings
/// before the branch, and any left at a negative displacement, are dropped. Returns the number of
/// rows dropped and `δ₀` (mm).
fn compensate_toe(rows: &mut Vec<Row>, [lo, hi]: [f64; 2], shown: &str) -> Result<(usize, f64)> {
    if !(lo > 0.0 && lo < hi && hi < 1.0) {
        return Err(CzError::config(
            format!("experiment `{shown}`, `toe_compensation`"),
            format!("[{lo}, {hi}] must be fractions of the peak load with 0 < min < max < 1, e.g. [0.2, 0.5]"),
        ));
    }
    if rows.is_empty() {
        return Err(CzError::data(shown, "toe compensation: no readings left"));
    }
    let peak_at = rows.iter().enumerate().fold(0, |m, (i, r)| if r.y > rows[m].y { i } else { m });
    let peak = rows[peak_at].y;
    let band: Vec<&Row> = rows[..=peak_at].iter().filter(|r| r.y >= lo * peak && r.y <= hi * peak).collect();
    let fail = |why: String| {
        CzError::data(
            shown,
            format!("toe compensation: {why}; choose `toe_compensation` around the straight part of the rising curve"),
        )
    };
    if band.len() < 3 {
        return Err(fail(format!(
            "{} reading(s) with loads between {lo} and {hi} × the peak load {peak} N before the peak, 3 are needed",
            band.len()
        )));
    }
    // Least squares of P on δ over the band.
    let n = band.len() as f64;
    let (mx, my) = (band.iter().map(|r| r.x).sum::<f64>() / n, band.iter().map(|r| r.y).sum::<f64>() / n);
    let sxy: f64 = band.iter().map(|r| (r.x - mx) * (r.y - my)).sum();
    let sxx: f64 = band.iter().map(|r| (r.x - mx).powi(2)).sum();
    let slope = sxy / sxx;
    if !(slope > 0.0 && slope.is_finite()) {
        return Err(fail(format!("the readings in the band do not rise (slope {slope} N/mm)")));
    }
    let zero = mx - my / slope;
    let first = rows.iter().position(|r| r.y >= lo * peak).unwrap_or(0);
    let before = rows.len();
    rows.drain(..first);
    rows.retain(|r| r.x - zero >= 0.0);
    for r in rows.iter_mut() {
        r.x -= zero;
    }
    Ok((before - rows.len(), zero))
}

/// Whether a used cell of `record` is empty or reads as a non-finite number (`NaN`, `inf`).
fn missing_or_non_finite(record: &csv::StringRecord, columns: &[Option<usize>]) -> bool {
    columns.iter().flatten().any(|&c| {
        let raw = record.get(c).unwrap_or("");
        raw.is_empty() || raw.parse::<f64>().is_ok_and(|v| !v.is_finite())
    })
}

/// One data row in czid units, with its line number in the file.
struct Row {
    line: usize,
    x: f64,
    y: f64,
    crack: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(file: &str) -> ExperimentSpec {
        ExperimentSpec {
            file: file.into(),
            displacement: "Disp".into(),
            load: "Force".into(),
            ordinate: Ordinate::Load,
            moment_unit: MomentUnit::NewtonMillimetre,
            crack: Some("CrackExt".into()),
            crack_measure: CrackMeasure::CrackLength,
            length_unit: LengthUnit::Millimetre,
            force_unit: ForceUnit::N,
            range: None,
            drop_non_increasing: false,
            drop_non_finite: false,
            toe_compensation: None,
            load_noise: None,
            length_noise: None,
        }
    }

    /// A scratch folder holding `text` as `t.csv`, removed when the test ends.
    fn write(name: &str, text: &str) -> tempfile::TempDir {
        let dir = tempfile::Builder::new().prefix(&format!("czid-data-{name}-")).tempdir().unwrap();
        std::fs::write(dir.path().join("t.csv"), text).unwrap();
        dir
    }

    #[test]
    fn reads_and_converts_crack_length_to_debonded_length() {
        let dir = write("ok", "Disp,Force,CrackExt\n0,0,40\n1,10,40\n2,15,42.5\n");
        let e = spec("t.csv").load(dir.path()).unwrap();
        assert_eq!(e.initial_crack, Some(40.0));
        assert_eq!(e.debonded_length.unwrap().y(), &[0.0, 0.0, 2.5]);
        assert_eq!(e.load.y(), &[0.0, 10.0, 15.0]);
    }

    #[test]
    fn converts_units() {
        let dir = write("units", "Disp,Force,CrackExt\n0,0,1\n0.001,0.01,1\n");
        let mut s = spec("t.csv");
        s.length_unit = LengthUnit::Metre;
        s.force_unit = ForceUnit::KiloNewton;
        let e = s.load(dir.path()).unwrap();
        assert_eq!(e.load.x(), &[0.0, 1.0]);
        assert_eq!(e.load.y(), &[0.0, 10.0]);
    }

    #[test]
    fn each_bad_input_names_what_and_where() {
        let cases = [
            ("missing-col", "Disp,Load,CrackExt\n0,0,1\n", "no column `Force`"),
            ("nonnum", "Disp,Force,CrackExt\n0,0,1\n1,abc,1\n", "row 3, column `Force`"),
            ("nan", "Disp,Force,CrackExt\n0,0,1\n1,NaN,1\n", "not a finite number"),
            ("empty", "Disp,Force,CrackExt\n", "no data rows"),
            ("decreasing", "Disp,Force,CrackExt\n0,0,1\n2,1,1\n1,1,1\n", "row 4, column `Disp`"),
        ];
        for (name, text, expect) in cases {
            let dir = write(name, text);
            let e = spec("t.csv").load(dir.path()).unwrap_err().to_string();
            assert!(e.contains(expect), "{name}: {e}");
            assert!(e.contains("t.csv"), "{name} must name the file: {e}");
        }
        let e = spec("absent.csv").load(Path::new("/nonexistent")).unwrap_err().to_string();
        assert!(e.contains("absent.csv"), "{e}");
    }

    #[test]
    fn non_increasing_rows_can_be_dropped() {
        let dir = write("drop", "Disp,Force,CrackExt\n0,0,1\n2,1,1\n1,1,1\n3,2,1\n");
        let mut s = spec("t.csv");
        s.drop_non_increasing = true;
        let e = s.load(dir.path()).unwrap();
        assert_eq!(e.load.x(), &[0.0, 2.0, 3.0]);
        assert_eq!(e.dropped, DroppedRows { non_increasing: 1, ..Default::default() });
    }

    #[test]
    fn rows_with_missing_or_non_finite_readings_can_be_dropped_and_are_counted() {
        let text = "Disp,Force,CrackExt\n0,0,1\n1,NaN,1\n2,,1\n3,3,NaN\n4,4,1\n";
        let dir = write("nan-rows", text);
        // By default the first such row is an error that says how to drop them.
        let e = spec("t.csv").load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("row 3, column `Force`") && e.contains("drop_non_finite"), "{e}");
        assert_eq!(e.matches("row 3").count(), 1, "the place is said once: {e}");
        let mut s = spec("t.csv");
        s.drop_non_finite = true;
        let e = s.load(dir.path()).unwrap();
        assert_eq!(e.load.x(), &[0.0, 4.0]);
        assert_eq!(e.dropped, DroppedRows { non_finite: 3, ..Default::default() });
        assert_eq!(e.dropped.describe().unwrap(), "rows dropped: 3 with a missing or non-finite reading");
        // A text cell is still an error: it is not a gap in the record but a wrong column.
        let dir = write("text-row", "Disp,Force,CrackExt\n0,0,1\n1,abc,1\n2,2,1\n");
        assert!(s.load(dir.path()).unwrap_err().to_string().contains("`abc` is not a number"));
    }

    #[test]
    fn a_seating_toe_is_compensated_by_the_line_through_the_rising_branch() {
        // A toe up to δ = 1 mm, then the straight branch P = 100 (δ − 0.5) to the peak at 3 mm,
        // then a drop: the zero moves to 0.5 mm and the toe's readings are dropped.
        let text = "Disp,Force,CrackExt\n0,0,1\n0.5,1,1\n0.8,20,1\n1.0,50,1\n1.5,100,1\n2.0,150,1\n\
                    2.5,200,1\n3.0,250,1\n3.5,120,1\n";
        let dir = write("toe", text);
        let mut s = spec("t.csv");
        s.toe_compensation = Some([0.15, 0.9]);
        let e = s.load(dir.path()).unwrap();
        assert!((e.dropped.toe_zero - 0.5).abs() < 1e-12, "{:?}", e.dropped);
        // 0, 0.5 (1 N) and 0.8 (20 N) lie below 0.15 × 250 N.
        assert_eq!(e.dropped.toe, 3);
        assert_eq!(e.load.x()[0], 0.5);
        assert_eq!(e.load.y()[0], 50.0);
        assert_eq!(*e.load.x().last().unwrap(), 3.0);
        let said = e.dropped.describe().unwrap();
        assert!(said.contains("3 in the seating toe") && said.contains("moved by 0.5000 mm"), "{said}");

        s.toe_compensation = Some([0.5, 0.2]);
        let err = s.load(dir.path()).unwrap_err().to_string();
        assert!(err.contains("toe_compensation") && err.contains("0 < min < max < 1"), "{err}");
        s.toe_compensation = Some([0.97, 0.99]);
        let err = s.load(dir.path()).unwrap_err().to_string();
        assert!(err.contains("3 are needed") && err.contains("t.csv"), "{err}");
    }

    #[test]
    fn reads_the_bundled_real_dcb_data() {
        let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/hartlen-dcb-enf");
        // DCB-03's opening increases throughout, so no row is dropped.
        let e = spec("DCB-03_Toughness.csv").load(&base).unwrap();
        assert_eq!(e.initial_crack, Some(25.391));
        // Documented in the data README: peak 91.4 N at 6.1 mm, final crack 79.3 mm.
        let peak = e.load.y().iter().cloned().fold(0.0, f64::max);
        assert!((peak - 91.4).abs() < 0.1, "peak {peak}");
        let growth = *e.debonded_length.unwrap().y().last().unwrap();
        assert!((growth + 25.391 - 79.3).abs() < 0.1, "final crack {}", growth + 25.391);
    }
}
