//! Plots of chosen signals against time, one panel per signal, as SVG.

use crate::master::Run;
use plotters::prelude::*;
use std::path::Path;

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
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let height = 260 * series.len().max(1) as u32 + 40;
    let root = SVGBackend::new(path, (1000, height)).into_drawing_area();
    let fail = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| fail(&e))?;
    let panels = root.split_evenly((series.len().max(1), 1));
    let t0 = *run.time.first().unwrap_or(&0.0);
    let t1 = *run.time.last().unwrap_or(&1.0);
    for ((name, ys), panel) in series.iter().zip(panels.iter()) {
        let (lo, hi) = ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
                (a.min(*y), b.max(*y))
            });
        let pad = ((hi - lo) * 0.05).max(1e-12);
        let mut chart = ChartBuilder::on(panel)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1.max(t0 + 1e-12), (lo - pad)..(hi + pad))
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(*name)
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(LineSeries::new(
                run.time.iter().copied().zip(ys.iter().copied()),
                &BLUE,
            ))
            .map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))
}
