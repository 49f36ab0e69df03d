//! What the timed sweeps leave behind: their CSV files and charts ([`super::chart`] draws them)
//! and the summary lines `raytree bench` prints (the Pareto-optimal settings, the crossovers).

use std::path::Path;

use super::chart::{Chart, Series, SeriesStyle, write_chart};
use super::measure::value_name;
use super::pareto::same_image;
use super::scaling::{LEVEL_WITHIN, ScalingOptions, ScalingPoint, Verdict, crossovers};
use super::sweep::{BenchPoint, BenchReport, Knob};
use crate::accel::AccelKind;
use crate::export::{ExportError, write_text};

/// Writes `bench.csv`, `bench.svg` and `bench.png` into `dir`.
pub fn write_bench(dir: &Path, report: &BenchReport, scene_name: &str) -> Result<(), ExportError> {
    write_text(&dir.join("bench.csv"), &bench_csv(report))?;
    write_chart(&bench_chart(report, scene_name), &dir.join("bench"))
}

/// Writes `scaling.csv`, `scaling.svg` and `scaling.png` into `dir`.
pub fn write_scaling(
    dir: &Path,
    points: &[ScalingPoint],
    opts: &ScalingOptions,
) -> Result<(), ExportError> {
    write_text(&dir.join("scaling.csv"), &scaling_csv(points))?;
    write_chart(
        &scaling_chart(points, opts.width, opts.height),
        &dir.join("scaling"),
    )
}

/// The sweep as CSV, one line per point.
pub fn bench_csv(report: &BenchReport) -> String {
    let mut s = String::from(
        "knob,value,max_depth,samples,cutoff,sphere,triangle,offset,accel,accel_used,secs,\
         build_secs,render_secs,rays,mrays_per_sec,mean_flip,rmse,psnr_db,differing_share,\
         changed_pixels,flip_vs_baseline,pareto\n",
    );
    for p in &report.points {
        let m = &p.settings.trace.methods;
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{},{:.3},{:.6},{:.6},{:.3},{:.6},{},{:.6},{}\n",
            p.knob.name(),
            p.value,
            p.settings.max_depth,
            p.settings.samples,
            p.settings.trace.cutoff,
            value_name(&m.sphere),
            value_name(&m.triangle),
            value_name(&m.offset),
            value_name(&p.settings.trace.accel),
            value_name(&p.accel_used),
            p.secs,
            p.build_secs,
            p.render_secs,
            p.rays,
            p.rays as f64 / p.render_secs.max(1e-9) / 1e6,
            p.error.mean_flip,
            p.error.rmse,
            p.error.psnr_db,
            p.error.differing_share,
            p.changed_pixels,
            p.flip_vs_baseline,
            p.pareto,
        ));
    }
    s
}

/// Mean FLIP against time on log axes, one series per knob, the Pareto front on top.
pub fn bench_chart(report: &BenchReport, scene_name: &str) -> Chart {
    let mut series: Vec<Series> = Knob::ALL
        .iter()
        .map(|&k| {
            let of_knob: Vec<&BenchPoint> = report.points.iter().filter(|p| p.knob == k).collect();
            let pts = of_knob
                .iter()
                .map(|p| (p.secs, p.error.mean_flip))
                .collect();
            let s = Series::new(k.name(), pts);
            match k {
                // Ordered values: a line; methods and accelerators: labelled points.
                Knob::MaxDepth | Knob::Samples | Knob::Cutoff => s,
                _ => s.styled(
                    SeriesStyle::Points,
                    of_knob.iter().map(|p| p.value.clone()).collect(),
                ),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let front_idx = report.pareto_front();
    let front = front_idx
        .iter()
        .map(|&i| {
            let secs = report.front_secs(i);
            (secs, report.points[i].error.mean_flip)
        })
        .collect();
    let labels = front_idx
        .iter()
        .map(|&i| {
            let p = &report.points[i];
            format!("{} {}", p.knob.name(), p.value)
        })
        .collect();
    series.push(Series::new("Pareto front", front).styled(SeriesStyle::Front, labels));
    Chart {
        title: format!(
            "{scene_name}: error against time ({}×{}, reference {} spp, depth {})",
            report.reference.width,
            report.reference.height,
            report.reference.samples,
            report.reference.max_depth
        ),
        x_label: "time per image, s (build + render, median)".into(),
        y_label: "mean FLIP against the reference".into(),
        x_log: true,
        y_log: true,
        series,
    }
}

/// The scaling sweep as CSV.
pub fn scaling_csv(points: &[ScalingPoint]) -> String {
    let mut s = String::from(
        "triangles,accel,build_secs,render_secs,total_secs,total_min_secs,total_max_secs,\
         memory_bytes,bytes_per_triangle,rays,note\n",
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{},{:.1},{},{}\n",
            p.triangles,
            value_name(&p.accel),
            p.build_secs,
            p.render_secs,
            p.total_secs(),
            p.total_min_secs,
            p.total_max_secs,
            p.memory_bytes,
            p.memory_bytes as f64 / p.triangles.max(1) as f64,
            p.rays,
            p.skipped.as_deref().unwrap_or(""),
        ));
    }
    s
}

/// Build + render time and build time alone against triangle count, log-log.
pub fn scaling_chart(points: &[ScalingPoint], width: u32, height: u32) -> Chart {
    let mut series = Vec::new();
    for kind in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        let measured: Vec<&ScalingPoint> = points
            .iter()
            .filter(|p| p.accel == kind && p.skipped.is_none())
            .collect();
        let name = value_name(&kind);
        series.push(Series::new(
            format!("{name}: build + render"),
            measured
                .iter()
                .map(|p| (p.triangles as f64, p.total_secs()))
                .collect(),
        ));
        if kind != AccelKind::None {
            series.push(Series::new(
                format!("{name}: build"),
                measured
                    .iter()
                    .map(|p| (p.triangles as f64, p.build_secs))
                    .collect(),
            ));
        }
    }
    Chart {
        title: format!("Tessellated sphere, {width}×{height}, 1 spp: time against triangle count"),
        x_label: "triangles".into(),
        y_label: "seconds".into(),
        x_log: true,
        y_log: true,
        series,
    }
}

/// The Pareto-optimal settings, one line each, fastest first.
pub fn pareto_lines(report: &BenchReport) -> Vec<String> {
    let same = report.points.iter().filter(|p| same_image(*p)).count();
    report
        .pareto_front()
        .into_iter()
        .map(|i| {
            let p = &report.points[i];
            let name = format!("{} = {}", p.knob.name(), p.value);
            let note = if same_image(p) {
                format!("  (the scene's own image; {same} settings give it)")
            } else {
                String::new()
            };
            format!(
                "{name:<22} {:>9.4} s  mean FLIP {:.4}  PSNR {:>6.2} dB  {:>10} rays{note}",
                report.front_secs(i),
                p.error.mean_flip,
                p.error.psnr_db,
                p.rays
            )
        })
        .collect()
}

/// The crossovers as sentences, one per pair of accelerators: which is faster over which
/// sizes, differences within [`LEVEL_WITHIN`] or the runs' spread called level, and where the
/// times cross. [`level_note`] says what level means.
pub fn crossover_lines(points: &[ScalingPoint]) -> Vec<String> {
    crossovers(points)
        .iter()
        .filter_map(|pair| {
            let (first, last) = (pair.stretches.first()?, pair.stretches.last()?);
            let whole = pair.stretches.len() == 1;
            let parts: Vec<String> = pair
                .stretches
                .iter()
                .map(|s| {
                    let who = match s.verdict {
                        Verdict::Faster(k) => format!("{} faster", value_name(&k)),
                        Verdict::Level => "level".to_string(),
                    };
                    let span = if first.from == last.to {
                        String::new()
                    } else if whole {
                        " at every size".to_string()
                    } else if s.from == s.to {
                        format!(" at {}", s.from)
                    } else if s.to == last.to {
                        format!(" from {} on", s.from)
                    } else {
                        format!(" from {} to {}", s.from, s.to)
                    };
                    let cross = s
                        .crosses_at
                        .map(|n| format!(" (the times cross at about {})", two_figures(n)))
                        .unwrap_or_default();
                    format!("{who}{span}{cross}")
                })
                .collect();
            let sizes = if first.from == last.to {
                crate::plural::count(last.to, "triangle")
            } else {
                format!(
                    "{}–{}",
                    first.from,
                    crate::plural::count(last.to, "triangle")
                )
            };
            Some(format!(
                "{} against {}, {sizes}: {}",
                value_name(&pair.a),
                value_name(&pair.b),
                parts.join("; ")
            ))
        })
        .collect()
}

/// What "level" means in [`crossover_lines`].
pub fn level_note() -> String {
    format!(
        "(level: the runs' ranges overlap or the medians are within {:.0} %)",
        LEVEL_WITHIN * 100.0
    )
}

/// `x` rounded to two significant figures: an interpolated crossing is no more precise.
fn two_figures(x: f64) -> u64 {
    if !x.is_finite() || x <= 0.0 {
        return 0;
    }
    let step = 10f64.powi((x.log10().floor() as i32 - 1).max(0));
    ((x / step).round() * step) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_crossover_line_per_pair_of_accelerators() {
        // Seconds of none, grid and BVH at 10, 1000 and 100 000 triangles (none not run there).
        let kinds = [AccelKind::None, AccelKind::Grid, AccelKind::Bvh];
        let pts: Vec<ScalingPoint> = [
            (10, [1.0, 1.02, 2.0]),
            (1000, [4.0, 1.0, 2.0]),
            (100_000, [f64::NAN, 1.0, 0.5]),
        ]
        .into_iter()
        .flat_map(|(n, secs)| {
            kinds
                .into_iter()
                .zip(secs)
                .filter(|(_, s)| !s.is_nan())
                .map(move |(k, s)| ScalingPoint::timed(n, k, s))
        })
        .collect();
        let lines = crossover_lines(&pts);
        assert_eq!(
            lines,
            [
                "none against grid, 10–1000 triangles: level at 10; grid faster at 1000",
                "none against bvh, 10–1000 triangles: none faster at 10; \
                 bvh faster at 1000 (the times cross at about 100)",
                "grid against bvh, 10–100000 triangles: grid faster from 10 to 1000; \
                 bvh faster at 100000 (the times cross at about 10000)",
            ]
        );
    }

    #[test]
    fn one_size_is_named_once() {
        let pts = [
            ScalingPoint::timed(1, AccelKind::None, 1.0),
            ScalingPoint::timed(1, AccelKind::Bvh, 3.0),
        ];
        assert_eq!(
            crossover_lines(&pts),
            ["none against bvh, 1 triangle: none faster"]
        );
    }

    #[test]
    fn a_crossing_is_given_to_two_figures() {
        assert_eq!(two_figures(1_289_774.0), 1_300_000);
        assert_eq!(two_figures(15.4), 15);
        assert_eq!(two_figures(1.03), 1);
        assert_eq!(two_figures(987.0), 990);
    }
}
