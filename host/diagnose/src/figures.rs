//! The figures of a diagnosis, drawn once for each backend: inline SVG for
//! `report.html` and PNG beside it (`gap.png`, `fit.png`, `law.png`,
//! `levels.png`, `residual.png`) for people who paste them into documents.
//!
//! - **gap**: held-out RMS error of the given model, the refitted one and
//!   after each effect, with the floor (noise and step error) drawn;
//! - **fit**: each measured channel against time with the given and final
//!   models, and their residuals underneath; the spans where each accepted
//!   effect earns its improvement shaded;
//! - **law**: the friction force the data imply against velocity, coloured
//!   by direction, with the nominal and final laws' steady sliding force;
//! - **levels** (position dependence only): the fitted level table against
//!   position;
//! - **residual**: the friction residual binned against velocity, position
//!   and displacement since reversal (mean ± standard deviation per bin),
//!   so outliers do not hide the trend.

use super::Diagnosis;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// One panel of [`draw_fit`]: its y label, every value on it (for the
/// range) and its series (values, colour, legend).
type Panel<'a> = (&'a str, Vec<f64>, Vec<(&'a [f64], RGBColor, &'a str)>);

/// One figure: its file stem, caption and inline SVG.
pub struct Figure {
    pub name: &'static str,
    pub caption: String,
    pub svg: String,
}

const GIVEN: RGBColor = RGBColor(200, 40, 40);
const FINAL: RGBColor = RGBColor(30, 90, 200);
const MEASURED: RGBColor = BLACK;
const POSITIVE: RGBColor = RGBColor(230, 120, 20);
const NEGATIVE: RGBColor = RGBColor(20, 150, 140);
/// Colours of the accepted effects' shaded spans, in order.
const EFFECT_COLOURS: [RGBColor; 4] = [
    RGBColor(120, 200, 80),
    RGBColor(240, 190, 40),
    RGBColor(180, 120, 220),
    RGBColor(90, 200, 220),
];

/// Draw `$draw(&root, $d)` as SVG (returned) and as `$dir/$name.png`.
macro_rules! render {
    ($dir:expr, $name:expr, $size:expr, $draw:ident, $d:expr) => {{
        let fail = |e: String| format!("{}.png: {e}", $dir.join($name).display());
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, $size).into_drawing_area();
            $draw(&root, $d).map_err(|e| fail(e.to_string()))?;
            root.present().map_err(|e| fail(e.to_string()))?;
        }
        let path = $dir.join(format!("{}.png", $name));
        let root = BitMapBackend::new(&path, $size).into_drawing_area();
        $draw(&root, $d).map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))?;
        svg
    }};
}

/// Every figure of `d`, each also written as PNG into `dir`.
pub fn draw_all(d: &Diagnosis, dir: &Path) -> Result<Vec<Figure>, String> {
    crate::plot::register_font()?;
    let mut out = vec![
        Figure {
            name: "gap",
            caption: "Held-out RMS error (normalised) of the model as given, its levels refitted, and after each effect found; the dashed line is the floor (measurement noise and the co-simulation's step error), below which no model can go.".into(),
            svg: render!(dir, "gap", (900, 380), draw_gap, d),
        },
        Figure {
            name: "fit",
            caption: "Held-out data: each measured channel (black) with the given model (red) and the final model (blue), and their residuals (measured − simulated) underneath. Shaded: where each effect found earns its improvement.".into(),
            svg: render!(
                dir,
                "fit",
                (1100, 420 * d.plots.channels.len().max(1) as u32 + 40),
                draw_fit,
                d
            ),
        },
        Figure {
            name: "law",
            caption: "The friction force the data imply against velocity (orange: moving forwards, teal: backwards), with the steady sliding force of the nominal law (red) and of the final law (blue) at the mean position.".into(),
            svg: render!(dir, "law", (900, 520), draw_law, d),
        },
    ];
    if d.final_model.position_dependent {
        out.push(Figure {
            name: "levels",
            caption: "The fitted Coulomb level along the travel (blue: forwards, teal: backwards; dots at the table's knots) against the nominal level (red).".into(),
            svg: render!(dir, "levels", (900, 420), draw_levels, d),
        });
    }
    out.push(Figure {
        name: "residual",
        caption: "The friction residual (force the data imply − law), held-out data, binned by each state: mean ± one standard deviation per bin of equal count, before the effects (red) and after (blue).".into(),
        svg: render!(dir, "residual", (1100, 900), draw_residual, d),
    });
    Ok(out)
}

/// The legend of `chart`'s labelled series at `position`, on a light box.
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> DrawResult<DB> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
}

/// The finite range of `v`, padded by 5 %.
fn range(v: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .into_iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if lo <= hi {
        let pad = ((hi - lo) * 0.05).max(1e-12 * lo.abs().max(1.0));
        (lo - pad, hi + pad)
    } else {
        (0.0, 1.0)
    }
}

/// The range holding the central 98 % of `v`, padded (outliers left out).
fn robust_range(v: &[f64]) -> (f64, f64) {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return (0.0, 1.0);
    }
    s.sort_by(f64::total_cmp);
    let q = |p: f64| s[((s.len() - 1) as f64 * p) as usize];
    range([q(0.01), q(0.99)])
}

/// At most 4000 evenly picked indices of `n`.
fn thinned(n: usize) -> impl Iterator<Item = usize> {
    (0..n).step_by(n.div_ceil(4000).max(1))
}

fn draw_gap<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, d: &Diagnosis) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let mut bars = vec![("as given".to_string(), d.nominal_rms, GIVEN)];
    if d.refit.heldout_rms.is_finite() {
        let kept = if d.refit.kept { "kept" } else { "not kept" };
        bars.push((
            format!("refitted ({kept})"),
            d.refit.heldout_rms,
            RGBColor(225, 140, 140),
        ));
    }
    for e in &d.effects {
        bars.push((format!("+ {}", e.name.name()), e.rms_after, FINAL));
    }
    let top = bars
        .iter()
        .map(|b| b.1)
        .fold(d.floor_rms, f64::max)
        .max(1e-300)
        * 1.15;
    let n = bars.len() as f64;
    let mut chart = ChartBuilder::on(root)
        .margin(15)
        .x_label_area_size(10)
        .y_label_area_size(80)
        .build_cartesian_2d(-0.5..n - 0.5, 0.0..top)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc("held-out RMS (normalised)")
        .y_label_formatter(&|y| crate::plot::tick_label(*y, 0.0, top))
        .draw()?;
    for (k, (label, value, colour)) in bars.iter().enumerate() {
        let x = k as f64;
        chart.draw_series(std::iter::once(Rectangle::new(
            [(x - 0.35, 0.0), (x + 0.35, *value)],
            colour.filled(),
        )))?;
        let style = ("sans-serif", 16).into_font().color(&BLACK);
        chart.draw_series(std::iter::once(Text::new(
            format!("{value:.4}"),
            (x - 0.3, value + top * 0.06),
            style.clone(),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            label.clone(),
            (x - 0.35, top * 0.985),
            style,
        )))?;
    }
    chart.draw_series(DashedLineSeries::new(
        [(-0.5, d.floor_rms), (n - 0.5, d.floor_rms)],
        8,
        5,
        BLACK.stroke_width(2),
    ))?;
    Ok(())
}

fn draw_fit<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, d: &Diagnosis) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let p = &d.plots;
    let (t0, t1) = range(p.time.iter().copied());
    let panels = root.split_evenly((2 * p.channels.len().max(1), 1));
    for (c, (name, measured, nominal, fin)) in p.channels.iter().enumerate() {
        let residual =
            |sim: &[f64]| -> Vec<f64> { measured.iter().zip(sim).map(|(m, s)| m - s).collect() };
        let (rn, rf) = (residual(nominal), residual(fin));
        let curves: [Panel; 2] = [
            (
                name.as_str(),
                [measured.as_slice(), nominal, fin].concat(),
                vec![
                    (measured.as_slice(), MEASURED, "measured"),
                    (nominal.as_slice(), GIVEN, "given model"),
                    (fin.as_slice(), FINAL, "final model"),
                ],
            ),
            (
                "residual",
                [rn.as_slice(), &rf].concat(),
                vec![
                    (rn.as_slice(), GIVEN, "measured − given"),
                    (rf.as_slice(), FINAL, "measured − final"),
                ],
            ),
        ];
        for (k, (y_name, all, series)) in curves.iter().enumerate() {
            let (lo, hi) = range(all.iter().copied());
            let mut chart = ChartBuilder::on(&panels[2 * c + k])
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(90)
                .build_cartesian_2d(t0..t1, lo..hi)?;
            chart
                .configure_mesh()
                .x_desc("time [s]")
                .y_desc(*y_name)
                .y_label_formatter(&|y| crate::plot::tick_label(*y, lo, hi))
                .draw()?;
            for (e, effect) in d.effects.iter().enumerate() {
                let colour = EFFECT_COLOURS[e % EFFECT_COLOURS.len()];
                chart
                    .draw_series(effect.where_.intervals.iter().map(|&(a, b)| {
                        Rectangle::new([(a, lo), (b, hi)], colour.mix(0.25).filled())
                    }))?
                    .label(format!("{}. {} earns here", e + 1, effect.name.name()))
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 15, y + 5)], colour.mix(0.5).filled())
                    });
            }
            for (ys, colour, label) in series {
                let colour = *colour;
                chart
                    .draw_series(
                        thinned(ys.len().min(p.time.len()))
                            .map(|i| Circle::new((p.time[i], ys[i]), 1, colour.filled())),
                    )?
                    .label(*label)
                    .legend(move |(x, y)| Circle::new((x + 7, y), 4, colour.filled()));
            }
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
    }
    Ok(())
}

/// The mean position and normal force of the held-out data.
fn mid_state(d: &Diagnosis) -> (f64, f64) {
    let p = &d.plots;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    (mean(&p.x), p.fn_.as_deref().map_or(1.0, mean))
}

fn draw_law<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, d: &Diagnosis) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let p = &d.plots;
    let (x_mid, fn_mid) = mid_state(d);
    let (v0, v1) = range(p.v.iter().copied());
    let grid: Vec<f64> = (0..=400)
        .map(|k| v0 + (v1 - v0) * k as f64 / 400.0)
        .collect();
    let law = |m: &super::model::FrictionModel| -> Vec<(f64, f64)> {
        grid.iter()
            .filter(|v| **v != 0.0)
            .map(|&v| (v, v.signum() * m.sliding_level(v, x_mid, fn_mid)))
            .collect()
    };
    let (nominal, fin) = (law(&d.nominal_model), law(&d.final_model));
    let (mut lo, mut hi) = robust_range(&p.force);
    for &(_, f) in nominal.iter().chain(&fin) {
        lo = lo.min(f * 1.1);
        hi = hi.max(f * 1.1);
    }
    let mut chart = ChartBuilder::on(root)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(v0..v1, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc("velocity v [m/s]")
        .y_desc("friction force [N]")
        .x_label_formatter(&|x| crate::plot::tick_label(*x, v0, v1))
        .y_label_formatter(&|y| crate::plot::tick_label(*y, lo, hi))
        .draw()?;
    for (positive, colour, label) in [
        (true, POSITIVE, "data, v > 0"),
        (false, NEGATIVE, "data, v < 0"),
    ] {
        chart
            .draw_series(
                thinned(p.v.len().min(p.force.len()))
                    .filter(|&i| (p.v[i] > 0.0) == positive && p.force[i] >= lo && p.force[i] <= hi)
                    .map(|i| Circle::new((p.v[i], p.force[i]), 1, colour.mix(0.5).filled())),
            )?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 7, y), 4, colour.filled()));
    }
    for (curve, colour, label) in [(nominal, GIVEN, "nominal law"), (fin, FINAL, "final law")] {
        // one line per direction: the law jumps at v = 0
        for side in [true, false] {
            let part: Vec<(f64, f64)> = curve
                .iter()
                .copied()
                .filter(|(v, _)| (*v > 0.0) == side)
                .collect();
            let series = chart.draw_series(LineSeries::new(part, colour.stroke_width(3)))?;
            if side {
                series.label(label).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 15, y)], colour.stroke_width(3))
                });
            }
        }
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    Ok(())
}

fn draw_levels<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, d: &Diagnosis) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let m = &d.final_model;
    let (x0, x1) = range(m.x_table.iter().copied().chain(d.plots.x.iter().copied()));
    let grid: Vec<f64> = (0..=300)
        .map(|k| x0 + (x1 - x0) * k as f64 / 300.0)
        .collect();
    let mut lines = vec![(
        "nominal".to_string(),
        grid.iter()
            .map(|&x| (x, d.nominal_model.level(true, x)))
            .collect::<Vec<_>>(),
        GIVEN,
    )];
    lines.push((
        "final, forwards".into(),
        grid.iter().map(|&x| (x, m.level(true, x))).collect(),
        FINAL,
    ));
    if m.direction_dependent {
        lines.push((
            "final, backwards".into(),
            grid.iter().map(|&x| (x, m.level(false, x))).collect(),
            NEGATIVE,
        ));
    }
    let (lo, hi) = range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(root)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, lo..hi)?;
    let unit = if m.normal_force_form { "N/N" } else { "N" };
    chart
        .configure_mesh()
        .x_desc("position x [m]")
        .y_desc(format!("Coulomb level [{unit}]"))
        .x_label_formatter(&|x| crate::plot::tick_label(*x, x0, x1))
        .y_label_formatter(&|y| crate::plot::tick_label(*y, lo, hi))
        .draw()?;
    for (label, points, colour) in lines {
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(3)))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 15, y)], colour.stroke_width(3)));
    }
    chart.draw_series(
        m.x_table
            .iter()
            .map(|&x| Circle::new((x, m.level(true, x)), 5, FINAL.filled())),
    )?;
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// (centre, mean, standard deviation) of `y` in `bins` bins of equal count
/// of `x`.
pub fn binned(x: &[f64], y: &[f64], bins: usize) -> Vec<(f64, f64, f64)> {
    let mut order: Vec<usize> = (0..x.len().min(y.len()))
        .filter(|&i| x[i].is_finite() && y[i].is_finite())
        .collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let n = order.len();
    (0..bins.min(n))
        .map(|b| {
            let members = &order[b * n / bins.min(n)..(b + 1) * n / bins.min(n)];
            let m = members.len().max(1) as f64;
            let centre = members.iter().map(|&i| x[i]).sum::<f64>() / m;
            let mean = members.iter().map(|&i| y[i]).sum::<f64>() / m;
            let var = members.iter().map(|&i| (y[i] - mean).powi(2)).sum::<f64>() / m;
            (centre, mean, var.sqrt())
        })
        .collect()
}

fn draw_residual<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &Diagnosis,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let p = &d.plots;
    let states: [(&str, &[f64]); 3] = [
        ("velocity v [m/s]", &p.v),
        ("position x [m]", &p.x),
        ("displacement since the last reversal [m]", &p.displacement),
    ];
    let panels = root.split_evenly((states.len(), 1));
    for ((label, xs), panel) in states.iter().zip(panels.iter()) {
        let before = binned(xs, &p.residual_before, 20);
        let after = binned(xs, &p.residual_after, 20);
        let (x0, x1) = range(before.iter().map(|b| b.0));
        let (lo, hi) = range(
            before
                .iter()
                .chain(&after)
                .flat_map(|&(_, m, s)| [m - s, m + s]),
        );
        let mut chart = ChartBuilder::on(panel)
            .margin(8)
            .x_label_area_size(35)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, lo..hi)?;
        chart
            .configure_mesh()
            .x_desc(*label)
            .y_desc("residual [N]")
            .x_label_formatter(&|x| crate::plot::tick_label(*x, x0, x1))
            .y_label_formatter(&|y| crate::plot::tick_label(*y, lo, hi))
            .draw()?;
        let shift = (x1 - x0) * 0.004;
        for (bins, colour, name, dx) in [
            (&before, GIVEN, "before the effects", -shift),
            (&after, FINAL, "final", shift),
        ] {
            chart.draw_series(bins.iter().map(|&(x, m, s)| {
                PathElement::new([(x + dx, m - s), (x + dx, m + s)], colour.stroke_width(2))
            }))?;
            chart
                .draw_series(
                    bins.iter()
                        .map(|&(x, m, _)| Circle::new((x + dx, m), 4, colour.filled())),
                )?
                .label(name)
                .legend(move |(x, y)| Circle::new((x + 7, y), 4, colour.filled()));
        }
        chart.draw_series(std::iter::once(PathElement::new(
            [(x0, 0.0), (x1, 0.0)],
            BLACK.mix(0.4),
        )))?;
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    Ok(())
}
