//! Line plots written as PNG or SVG (chosen by the file extension), atomically.
//!
//! A small layer over `plotters` with a bundled font (DejaVu Sans, Bitstream Vera licence in
//! `optimizers/assets/`), so plots render identically on machines without system fonts. Every
//! plot of czid (benchmark harness, identification fits, comparisons) is drawn with this font.
//!
//! ```no_run
//! use czid_optimizers::plot::{Figure, Series};
//! Figure::new("DCB", "opening (mm)", "load (N)")
//!     .with(Series::line("model", vec![0.0, 1.0, 2.0], vec![0.0, 10.0, 8.0]))
//!     .with(Series::points("test", vec![0.5, 1.5], vec![5.0, 9.0]))
//!     .save(std::path::Path::new("out/load.png"))
//!     .unwrap();
//! ```

use czid_core::{CzError, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the bundled font as `sans-serif` (once per process).
pub fn register_font() {
    REGISTER.call_once(|| {
        // The font is bundled and known to be valid; a failure here would leave text unrendered,
        // never corrupt a plot, so it is not worth surfacing.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mark {
    /// Connected line.
    Line,
    /// Dashed line.
    Dashed,
    /// Unconnected markers (typically test data).
    Points,
}

/// One data series.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Drawing style.
    pub mark: Mark,
    /// Optional shaded band `(lower, upper)` around the series (e.g. quartiles over seeds).
    pub band: Option<(Vec<f64>, Vec<f64>)>,
}

impl Series {
    /// A line.
    pub fn line(label: &str, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series { label: label.into(), x, y, mark: Mark::Line, band: None }
    }
    /// A dashed line.
    pub fn dashed(label: &str, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series { label: label.into(), x, y, mark: Mark::Dashed, band: None }
    }
    /// Markers.
    pub fn points(label: &str, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series { label: label.into(), x, y, mark: Mark::Points, band: None }
    }
    /// Adds a band between `lower` and `upper`: shaded around a line, error bars on markers.
    pub fn with_band(mut self, lower: Vec<f64>, upper: Vec<f64>) -> Self {
        self.band = Some((lower, upper));
        self
    }
}

/// A vertical marker line with a label (e.g. a regime boundary).
#[derive(Clone, Debug, PartialEq)]
pub struct VLine {
    /// Label written next to the line.
    pub label: String,
    /// Abscissa.
    pub x: f64,
}

/// A single-panel figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Title.
    pub title: String,
    /// Abscissa label (with unit).
    pub x_label: String,
    /// Ordinate label (with unit).
    pub y_label: String,
    /// Series, drawn in order.
    pub series: Vec<Series>,
    /// Vertical markers.
    pub vlines: Vec<VLine>,
    /// Logarithmic ordinate.
    pub log_y: bool,
    /// Names shown at the abscissae 1, 2, … instead of numbers (a categorical axis); empty: numbers.
    pub categories: Vec<String>,
    /// Size in pixels.
    pub size: (u32, u32),
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

impl Figure {
    /// An empty figure.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            vlines: Vec::new(),
            log_y: false,
            categories: Vec::new(),
            size: (900, 600),
        }
    }

    /// Adds a series.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a vertical marker.
    pub fn with_vline(mut self, label: &str, x: f64) -> Self {
        self.vlines.push(VLine { label: label.into(), x });
        self
    }

    /// Names the abscissae 1, 2, …: a categorical axis (e.g. one column of points per optimizer).
    pub fn with_categories(mut self, names: &[String]) -> Self {
        self.categories = names.to_vec();
        self
    }

    /// Uses a logarithmic ordinate.
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// Writes the figure to `path` (`.png` or `.svg`) through a temporary file and a rename, so
    /// an interrupted run never leaves a half-written plot.
    pub fn save(&self, path: &Path) -> Result<()> {
        register_font();
        let io = |e: &dyn std::fmt::Display| CzError::Io { path: path.display().to_string(), message: e.to_string() };
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        let tmp = path.with_extension(format!("partial.{ext}"));
        match ext.as_str() {
            "png" => {
                let root = BitMapBackend::new(&tmp, self.size).into_drawing_area();
                self.draw(root).map_err(|e| io(&e))?;
            }
            "svg" => {
                let root = SVGBackend::new(&tmp, self.size).into_drawing_area();
                self.draw(root).map_err(|e| io(&e))?;
            }
            _ => return Err(CzError::config(path.display().to_string(), "plot files must end in .png or .svg")),
        }
        std::fs::rename(&tmp, path).map_err(|e| io(&e))
    }

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if x.is_finite() && y.is_finite() && (!self.log_y || y > 0.0) {
                    xr = (xr.0.min(x), xr.1.max(x));
                    yr = (yr.0.min(y), yr.1.max(y));
                }
            }
            if let Some((lo, hi)) = &s.band {
                for &y in lo.iter().chain(hi) {
                    if y.is_finite() && (!self.log_y || y > 0.0) {
                        yr = (yr.0.min(y), yr.1.max(y));
                    }
                }
            }
        }
        if !xr.0.is_finite() {
            xr = (0.0, 1.0);
        }
        if !yr.0.is_finite() {
            yr = if self.log_y { (1e-3, 1.0) } else { (0.0, 1.0) };
        }
        if !self.categories.is_empty() {
            // Half a category of room on either side, so that the first and last columns and
            // their names are not cut by the frame.
            xr = (0.5, self.categories.len() as f64 + 0.5);
        }
        if xr.1 <= xr.0 {
            xr.1 = xr.0 + 1.0;
        }
        if self.log_y {
            if yr.1 <= yr.0 {
                yr.1 = yr.0 * 10.0;
            }
            (xr, (yr.0 / 1.5, yr.1 * 1.5))
        } else {
            let pad = 0.05 * (yr.1 - yr.0).max(1e-12);
            let lo = if yr.0 >= 0.0 && yr.0 < 0.2 * yr.1 { 0.0 } else { yr.0 - pad };
            (xr, (lo, yr.1 + pad))
        }
    }

    /// An abscissa tick label: the category at an integer position, else the number.
    fn x_tick(&self, x: f64) -> String {
        if self.categories.is_empty() {
            return tick(x);
        }
        let k = x.round();
        if (x - k).abs() < 1e-6 && k >= 1.0 && k as usize <= self.categories.len() {
            self.categories[k as usize - 1].clone()
        } else {
            String::new()
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut builder = ChartBuilder::on(&root);
        builder.caption(&self.title, ("sans-serif", 24)).margin(15).x_label_area_size(45).y_label_area_size(70);
        if self.log_y {
            let mut chart = builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .x_label_formatter(&|x| self.x_tick(*x))
                .y_label_formatter(&|y| tick(*y))
                .label_style(("sans-serif", 15))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            self.draw_series(&mut chart, (y0, y1))?;
        } else {
            let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .x_label_formatter(&|x| self.x_tick(*x))
                .y_label_formatter(&|y| tick(*y))
                .label_style(("sans-serif", 15))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            self.draw_series(&mut chart, (y0, y1))?;
        }
        root.present().map_err(err)
    }

    fn draw_series<'a, DB, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, Y>>,
        (y0, y1): (f64, f64),
    ) -> std::result::Result<(), String>
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        Y: Ranged<ValueType = f64>,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let ok = |x: f64, y: f64| x.is_finite() && y.is_finite() && (!self.log_y || y > 0.0);
        for (i, s) in self.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            if let (Some((lo, hi)), Mark::Points) = (&s.band, s.mark) {
                // Markers carry their band as error bars: one vertical bar per point.
                let bars =
                    s.x.iter().zip(lo.iter().zip(hi)).filter(|(x, (a, b))| ok(**x, **a) && ok(**x, **b) && a < b);
                chart
                    .draw_series(
                        bars.map(|(&x, (&a, &b))| PathElement::new(vec![(x, a), (x, b)], color.stroke_width(2))),
                    )
                    .map_err(err)?;
            } else if let Some((lo, hi)) = &s.band {
                let mut poly: Vec<(f64, f64)> =
                    s.x.iter().zip(hi).filter(|(x, y)| ok(**x, **y)).map(|(x, y)| (*x, *y)).collect();
                poly.extend(s.x.iter().zip(lo).rev().filter(|(x, y)| ok(**x, **y)).map(|(x, y)| (*x, *y)));
                chart.draw_series(std::iter::once(Polygon::new(poly, color.mix(0.2).filled()))).map_err(err)?;
            }
            let pts: Vec<(f64, f64)> =
                s.x.iter().zip(&s.y).filter(|(x, y)| ok(**x, **y)).map(|(x, y)| (*x, *y)).collect();
            let style = ShapeStyle::from(&color).stroke_width(2);
            let anno = match s.mark {
                Mark::Line => chart.draw_series(LineSeries::new(pts, style)).map_err(err)?,
                Mark::Dashed => chart.draw_series(DashedLineSeries::new(pts, 8, 5, style)).map_err(err)?,
                Mark::Points => {
                    // Few points per column on a categorical axis: larger marks.
                    let r = if self.categories.is_empty() { 2 } else { 5 };
                    chart.draw_series(pts.into_iter().map(|p| Circle::new(p, r, color.filled()))).map_err(err)?
                }
            };
            anno.label(s.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], ShapeStyle::from(&color).stroke_width(2))
            });
        }
        for v in &self.vlines {
            let grey = RGBColor(120, 120, 120);
            chart.draw_series(LineSeries::new(vec![(v.x, y0), (v.x, y1)], grey.stroke_width(1))).map_err(err)?;
            chart
                .draw_series(std::iter::once(Text::new(v.label.clone(), (v.x, y1), ("sans-serif", 13).into_font())))
                .map_err(err)?;
        }
        if self.series.iter().any(|s| !s.label.is_empty()) {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 15))
                .draw()
                .map_err(err)?;
        }
        Ok(())
    }
}

/// A short tick label: plain digits for moderate magnitudes, scientific notation otherwise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-2..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        let s = format!("{v:.2e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short_and_exact() {
        assert_eq!(super::tick(0.0), "0");
        assert_eq!(super::tick(2.5), "2.5");
        assert_eq!(super::tick(120.0), "120");
        assert_eq!(super::tick(0.0125), "0.0125");
        assert_eq!(super::tick(3e-4), "3e-4");
        assert_eq!(super::tick(1.5e-4), "1.5e-4");
        assert_eq!(super::tick(2.5e6), "2.5e6");
        let f = Figure::new("t", "x", "y").with_categories(&["miga".into(), "lm".into()]);
        assert_eq!(
            (f.x_tick(1.0), f.x_tick(2.0), f.x_tick(1.5), f.x_tick(3.0)),
            ("miga".into(), "lm".into(), "".into(), "".into())
        );
    }

    #[test]
    fn writes_png_and_svg_and_rejects_other_extensions() {
        let dir = std::env::temp_dir().join(format!("czid-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fig = Figure::new("t", "x (mm)", "y (N)")
            .with(Series::line("a", vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.5]).with_band(vec![0.0; 3], vec![1.5; 3]))
            .with(Series::points("b", vec![0.5], vec![0.7]))
            .with_vline("peak", 1.0);
        for name in ["f.png", "f.svg"] {
            let p = dir.join(name);
            fig.save(&p).unwrap();
            assert!(std::fs::metadata(&p).unwrap().len() > 1000, "{name} is too small to hold a plot");
        }
        assert!(fig.save(&dir.join("f.pdf")).is_err());
        // Markers with a band get one error bar per point (a drawn segment each), not a shaded area.
        let marked = |band: bool| {
            let s = Series::points("b", vec![1.0, 2.0], vec![5.0, 7.0]);
            let s = if band { s.with_band(vec![4.0, 6.5], vec![6.0, 7.5]) } else { s };
            let p = dir.join(format!("bars-{band}.svg"));
            Figure::new("t", "x", "y").with(s).save(&p).unwrap();
            let text = std::fs::read_to_string(&p).unwrap();
            // Strokes of the series' width: its legend entry, and the bars.
            (text.matches("stroke-width=\"2\"").count(), text.matches("<polygon").count())
        };
        let (plain, bars) = (marked(false), marked(true));
        assert_eq!(plain, (1, 0));
        assert_eq!(bars, (3, 0));
        let log = Figure::new("t", "x", "y").log_y().with(Series::line("a", vec![0.0, 1.0], vec![1.0, 1e-3]));
        log.save(&dir.join("log.png")).unwrap();
        if std::env::var_os("CZID_KEEP_PLOTS").is_none() {
            std::fs::remove_dir_all(&dir).ok();
        }
    }
}
