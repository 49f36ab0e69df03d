//! What the timed sweeps leave behind: their CSV files and charts ([`super::chart`] draws them)
//! and the summary lines `raytree bench` prints (the Pareto-optimal settings, the crossovers).

use std::path::Path;

use super::chart::{Chart, Series, SeriesStyle, write_chart};
use super::measure::value_name;
use super::pareto::same_image;
use super::scaling::{ScalingOptions, ScalingPoint, crossovers};
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
            "{scene_name}: error against time ({}x{}, reference {} spp, depth {})",
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
        "triangles,accel,build_secs,render_secs,total_secs,memory_bytes,bytes_per_triangle,rays,note\n",
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{:.6},{:.6},{:.6},{},{:.1},{},{}\n",
            p.triangles,
            value_name(&p.accel),
            p.build_secs,
            p.render_secs,
            p.total_secs(),
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
        title: format!("Tessellated sphere, {width}x{height}, 1 spp: time against triangle count"),
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

/// The crossovers as sentences.
pub fn crossover_lines(points: &[ScalingPoint]) -> Vec<String> {
    let smallest = points.iter().map(|p| p.triangles).min().unwrap_or(0);
    crossovers(points)
        .iter()
        .map(|(first, other, changes)| {
            let mut line = format!(
                "{} is faster than {} at {smallest} triangles",
                value_name(first),
                value_name(other)
            );
            for c in changes {
                line.push_str(&format!(
                    "; {} is faster from about {:.0}",
                    value_name(&c.faster),
                    c.triangles
                ));
            }
            line
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_crossover_line_per_pair_of_accelerators() {
        // Seconds of none, grid and BVH at 10 and at 1000 triangles.
        let kinds = [AccelKind::None, AccelKind::Grid, AccelKind::Bvh];
        let pts: Vec<ScalingPoint> = [(10, [1.0, 1.0, 2.0]), (1000, [4.0, 1.0, 2.0])]
            .into_iter()
            .flat_map(|(n, secs)| {
                kinds
                    .into_iter()
                    .zip(secs)
                    .map(move |(k, s)| ScalingPoint::timed(n, k, s))
            })
            .collect();
        let lines = crossover_lines(&pts);
        assert_eq!(lines.len(), 3);
        assert_eq!(
            lines[1],
            "none is faster than bvh at 10 triangles; bvh is faster from about 100"
        );
    }
}
