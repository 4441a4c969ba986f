//! Runs the MMB of the bench (`Mmb::hartlen_half_mode_two`: G_II/G = 0.5, to 7 mm) over a
//! population of laws drawn in the box of `examples/mixed-mode-synthetic/problem.toml`
//! (`benches/common/population.rs`), on the window and on the whole mesh, and compares them:
//!
//! `cargo run --release --example mmb_population -- [laws]` (default 40)
//!
//! Per law: whether the window ran it (or why not), the largest load difference at the output
//! abscissae both records share (relative to the whole mesh's peak), and the two run times; then
//! the median and worst difference and the median ratio of the times.

#[allow(dead_code)] // the DCB populations are the other includers'
#[path = "../benches/common/population.rs"]
mod population;

use czid_models::mmb::Mmb;
use std::time::Instant;

fn main() {
    let n: usize = match std::env::args().nth(1) {
        None => 40,
        Some(arg) => match arg.parse() {
            Ok(n) if n > 0 => n,
            _ => {
                eprintln!("mmb_population: the number of laws must be a positive integer, not `{arg}`");
                std::process::exit(2);
            }
        },
    };
    let (mmb, _) = Mmb::hartlen_half_mode_two();
    let (mut worst, mut ratios, mut windowed) = (Vec::new(), Vec::new(), 0);
    for (i, law) in population::mixed_mode_laws(n, 7).iter().enumerate() {
        let t = Instant::now();
        let window = mmb.run_rows(law);
        let t_window = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let whole = mmb.run_rows_whole_mesh(law);
        let t_whole = t.elapsed().as_secs_f64();
        let ((rows, stats), (reference, _)) = match (window, whole) {
            (Ok(a), Ok(b)) => (a, b),
            (a, b) => {
                println!("law {i}: window {}, whole mesh {}", a.is_ok(), b.is_ok());
                continue;
            }
        };
        windowed += usize::from(stats.windowed);
        ratios.push(t_whole / t_window);
        // Both records hold the output grid; the whole mesh also records states along snap-backs.
        let peak = reference.iter().map(|r| r.reaction.abs()).fold(0.0, f64::max);
        let end = reference.last().map_or(1.0, |r| r.control.abs());
        let mut largest = 0.0f64;
        for r in &rows {
            let at = reference.iter().rev().find(|s| (s.control - r.control).abs() <= 1e-9 * end);
            if let Some(s) = at {
                largest = largest.max((r.reaction - s.reaction).abs() / peak);
            }
        }
        worst.push(largest);
        println!(
            "law {i}: {}, load difference {largest:.1e} of the peak, {:.1} ms against {:.1} ms",
            if stats.windowed { "window".to_string() } else { format!("whole mesh ({:?})", stats.window_fallback) },
            1e3 * t_window,
            1e3 * t_whole
        );
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let largest = worst.iter().copied().fold(0.0, f64::max);
    let below = worst.iter().filter(|w| **w <= 1e-8).count();
    println!(
        "{} laws: {windowed} on the window; load differences median {:.1e}, largest {largest:.1e}, {below} within 1e-8 of the peak; whole mesh / window time median {:.2}",
        worst.len(),
        median(&mut worst),
        median(&mut ratios)
    );
}
