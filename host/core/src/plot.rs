//! Plots of chosen signals against time, one panel per signal, as PNG
//! (plotters' bitmap backend) or SVG, chosen by the file's extension.
//!
//! Text is drawn with DejaVu Sans, compiled into the binary
//! (`host/core/assets/DejaVuSans.ttf`, Bitstream Vera licence beside it) and
//! registered with plotters' pure-Rust `ab_glyph` renderer, so a plot looks
//! the same on every machine and needs no system font library.

use crate::master::Run;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Register the font under "sans-serif" once per process.
pub fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
                .map_err(|_| "the compiled-in font DejaVu Sans could not be read".to_string())
        })
        .clone()
}

/// Plot `signals` (column names of `run`) into `path` (`.png` or `.svg`).
pub fn plot_signals(run: &Run, signals: &[String], path: &Path, title: &str) -> Result<(), String> {
    let mut series = Vec::new();
    for s in signals {
        let k = run.columns.iter().position(|c| c == s).ok_or_else(|| {
            format!(
                "cannot plot `{s}`: no such column (columns: {})",
                run.columns.join(", ")
            )
        })?;
        series.push((
            s.as_str(),
            run.rows.iter().map(|r| r[k]).collect::<Vec<f64>>(),
        ));
    }
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(extension.as_deref(), Some("png" | "svg")) {
        return Err(format!(
            "plot {}: the file name must end in .png or .svg",
            path.display()
        ));
    }
    register_font()?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let size = (1000, 260 * series.len().max(1) as u32 + 40);
    let fail = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    if extension.as_deref() == Some("png") {
        let root = BitMapBackend::new(path, size).into_drawing_area();
        draw(&root, run, &series, title).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))
    } else {
        let root = SVGBackend::new(path, size).into_drawing_area();
        draw(&root, run, &series, title).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))
    }
}

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    series: &[(&str, Vec<f64>)],
    title: &str,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let panels = root.split_evenly((series.len().max(1), 1));
    let t0 = *run.time.first().unwrap_or(&0.0);
    let t1 = *run.time.last().unwrap_or(&1.0);
    for ((name, ys), panel) in series.iter().zip(panels.iter()) {
        let (lo, hi) = ys
            .iter()
            .filter(|y| y.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
                (a.min(*y), b.max(*y))
            });
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        let pad = ((hi - lo) * 0.05).max(1e-12);
        let mut chart = ChartBuilder::on(panel)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1.max(t0 + 1e-12), (lo - pad)..(hi + pad))?;
        let (a, b) = (lo - pad, hi + pad);
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(*name)
            .y_label_formatter(&|y| tick_label(*y, a, b))
            .draw()?;
        chart.draw_series(LineSeries::new(
            run.time.iter().copied().zip(ys.iter().copied()),
            &BLUE,
        ))?;
    }
    Ok(())
}

/// A y-axis tick label that tells the ticks of the range `lo..hi` apart at
/// any scale (plotters' default prints `0.0` for every tick of a signal in
/// micrometres): decimals for magnitudes from 1e-3 to 1e5, scientific
/// notation otherwise, with digits down to a twentieth of the range.
pub fn tick_label(y: f64, lo: f64, hi: f64) -> String {
    if y == 0.0 || !y.is_finite() {
        return format!("{y}");
    }
    let magnitude = lo.abs().max(hi.abs());
    let resolution = ((hi - lo).abs() / 20.0).max(magnitude * 1e-12);
    if !(magnitude.is_finite() && resolution > 0.0) {
        return format!("{y}");
    }
    // a tick at zero that rounding moved off it (-3e-21 on a range of 1e-5)
    if y.abs() < resolution * 1e-6 {
        return "0".into();
    }
    let finest = resolution.log10().floor() as i32;
    if (1e-3..1e5).contains(&magnitude) {
        format!("{:.*}", (-finest).max(0) as usize, y)
    } else {
        let leading = y.abs().log10().floor() as i32;
        format!("{:.*e}", (leading - finest).clamp(0, 12) as usize, y)
    }
}

#[cfg(test)]
mod tests {
    use super::tick_label;

    #[test]
    fn tick_labels_resolve_micrometres_and_newtons() {
        // a body position in micrometres: distinct, readable labels
        let labels: Vec<String> = (0..=6)
            .map(|i| tick_label(i as f64 * 1e-7, 0.0, 6e-7))
            .collect();
        assert_eq!(
            labels,
            ["0", "1.0e-7", "2.0e-7", "3.0e-7", "4.0e-7", "5.0e-7", "6.0e-7"]
        );
        // a narrow range far from zero keeps the digits that differ
        assert_eq!(tick_label(5.7937e-7, 5.7936e-7, 5.794e-7), "5.79370e-7");
        // forces in newtons and large values
        assert_eq!(tick_label(0.15, -0.22, 0.22), "0.15");
        assert_eq!(tick_label(2.5, 0.0, 10.0), "2.5");
        assert_eq!(tick_label(250000.0, 0.0, 1e6), "2.5e5");
        assert_eq!(tick_label(f64::NAN, 0.0, 1.0), "NaN");
        // zero, rounded off it
        assert_eq!(tick_label(-3e-21, -2e-5, 3e-5), "0");
    }
}
