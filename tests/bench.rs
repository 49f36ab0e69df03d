//! `raytree bench SCENE --quick --out DIR`: the speed/accuracy sweep and the scaling sweep
//! write their CSV files and charts, accelerators never change the image, and the error falls
//! as samples are added. (The figures themselves are benchmarks, never asserted as timings.)

use std::collections::HashMap;
use std::path::Path;

use assert_cmd::Command;

/// The CSV as rows of column → value.
fn read_csv(path: &Path) -> (Vec<String>, Vec<HashMap<String, String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header line")
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{}: {l}", path.display());
            header
                .iter()
                .cloned()
                .zip(cells.iter().map(|c| c.to_string()))
                .collect()
        })
        .collect();
    (header, rows)
}

fn assert_columns(header: &[String], cols: &[&str]) {
    for col in cols {
        assert!(
            header.iter().any(|h| h == col),
            "no column {col}: {header:?}"
        );
    }
}

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {:?} is not a number", row[col]))
}

fn assert_chart(dir: &Path, stem: &str) {
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("svg");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    let png = std::fs::read(dir.join(format!("{stem}.png"))).expect("png");
    assert_eq!(&png[1..4], b"PNG");
    assert!(png.len() < 300_000, "{stem}.png is {} bytes", png.len());
}

/// `raytree bench SCENE --quick --out DIR`.
fn quick_bench(scene: &str, dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
        .args(["bench", scene, "--quick", "--out"])
        .arg(dir)
        .output()
        .expect("run")
}

#[test]
fn quick_bench_writes_csv_and_charts() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = quick_bench("default", dir.path());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Pareto-optimal settings"), "{stdout}");
    assert!(stdout.contains("0 differing pixels"), "{stdout}");
    // One sentence per pair of accelerators, over the sizes both were run at.
    for pair in [
        "none against grid, 1–",
        "none against bvh, 1–",
        "grid against bvh, 1–",
    ] {
        assert_eq!(stdout.matches(pair).count(), 1, "{pair}: {stdout}");
    }
    assert!(stdout.contains("(level: "), "{stdout}");

    let (header, rows) = read_csv(&dir.path().join("bench.csv"));
    // Each knob is a column of its own too (the value every point was rendered with).
    const KNOBS: [&str; 7] = [
        "max_depth",
        "samples",
        "cutoff",
        "sphere",
        "triangle",
        "offset",
        "accel",
    ];
    assert_columns(&header, &KNOBS);
    assert_columns(
        &header,
        &[
            "knob",
            "value",
            "secs",
            "rays",
            "mean_flip",
            "rmse",
            "psnr_db",
            "differing_share",
            "changed_pixels",
            "pareto",
        ],
    );
    let knob = |k: &'static str| rows.iter().filter(move |r| r["knob"] == k);
    for k in KNOBS {
        assert!(knob(k).count() >= 2, "knob {k}");
    }
    assert_eq!(knob("max_depth").count(), 13, "max depth 0 to 12");
    // Accelerators must not change the image.
    for r in knob("accel") {
        assert_eq!(r["changed_pixels"], "0", "{r:?}");
    }
    // More samples, less error: FLIP and RMSE fall from 1 sample to the most.
    let samples: Vec<&HashMap<String, String>> = knob("samples").collect();
    let (first, last) = (samples[0], samples[samples.len() - 1]);
    assert_eq!(first["samples"], "1");
    for col in ["mean_flip", "rmse"] {
        assert!(
            num(last, col) < 0.7 * num(first, col),
            "{col}: {} samples {} vs 1 sample {}",
            last["samples"],
            num(last, col),
            num(first, col)
        );
        for w in samples.windows(2) {
            assert!(
                num(w[1], col) <= num(w[0], col) * 1.02,
                "{col} rises: {w:?}"
            );
        }
    }
    // Depth 0 (no reflections or refractions) is far from the reference.
    let d0 = knob("max_depth").next().expect("depth 0");
    assert!(num(d0, "mean_flip") > num(last, "mean_flip"));
    assert!(rows.iter().any(|r| r["pareto"] == "true"));
    for r in &rows {
        assert!(num(r, "secs") > 0.0 && num(r, "rays") > 0.0, "{r:?}");
        let flip = num(r, "mean_flip");
        assert!((0.0..=1.0).contains(&flip), "{r:?}");
    }
    assert_chart(dir.path(), "bench");

    let (header, rows) = read_csv(&dir.path().join("scaling.csv"));
    assert_columns(
        &header,
        &[
            "triangles",
            "accel",
            "build_secs",
            "render_secs",
            "total_min_secs",
            "total_max_secs",
            "memory_bytes",
            "note",
        ],
    );
    for accel in ["none", "grid", "bvh"] {
        assert!(rows.iter().any(|r| r["accel"] == accel), "{accel}");
    }
    assert!(rows.iter().any(|r| num(r, "triangles") >= 8000.0));
    for r in rows.iter().filter(|r| r["note"].is_empty()) {
        let (min, max) = (num(r, "total_min_secs"), num(r, "total_max_secs"));
        assert!(min > 0.0 && min <= max, "{r:?}");
    }
    assert_chart(dir.path(), "scaling");
}

#[test]
fn bench_refuses_a_missing_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = quick_bench("no-such-scene.toml", dir.path());
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}
