//! A render on a real Slurm cluster: starts a one-node cluster on this machine
//! (scripts/slurm/start-cluster.sh: munged, slurmctld, slurmd as root, no systemd), renders a
//! built-in scene as 4 tiles through `sbatch --array=0-3` with the merge waiting on the array
//! by a dependency (scripts/slurm/submit-tiles.sh), and a turntable through a second array
//! (render-frames.sbatch); then compares the merged image with the single-machine render bit
//! for bit, and the frames byte for byte. The cluster is torn down at the end, on failure too,
//! and the test checks its daemons are gone.
//!
//! When the cluster cannot start (no root, Slurm or munge missing: scripts/install-deps.sh
//! installs them) the test fails, saying why. Every wait has a timeout.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use raytree::export::{Pixels, read_stamped};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const RAYTREE: &str = env!("CARGO_BIN_EXE_raytree");
/// The scene and size every part is rendered at.
const RENDER: &[&str] = &["--width", "160", "--height", "120", "--samples", "2"];

/// What a finished command said.
struct Ran {
    ok: bool,
    stdout: String,
    stderr: String,
}

/// Runs `cmd` with its output in files (no pipe to fill), killing it after `timeout`.
fn run(cmd: &mut Command, what: &str, timeout: Duration) -> Ran {
    let dir = tempfile::tempdir().expect("temp dir");
    let (out, err) = (dir.path().join("out"), dir.path().join("err"));
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(File::create(&out).expect("out file"))
        .stderr(File::create(&err).expect("err file"))
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {what}: {e}"));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    let mut stderr = read(&err);
    if status.is_none() {
        stderr += &format!("\n{what} did not finish within {} s", timeout.as_secs());
    }
    Ran {
        ok: status.is_some_and(|s| s.success()),
        stdout: read(&out),
        stderr,
    }
}

/// The cluster's daemons (name, process id) as start-cluster.sh recorded them.
fn daemons(dir: &Path) -> Vec<(String, u32)> {
    ["munged", "slurmctld", "slurmd"]
        .iter()
        .filter_map(|d| {
            let text = std::fs::read_to_string(dir.join(format!("{d}.launcher.pid"))).ok()?;
            Some((d.to_string(), text.trim().parse().ok()?))
        })
        .collect()
}

/// Whether process `pid` is still daemon `name` (not ended, not a reused id).
fn alive(name: &str, pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/comm"))
        .is_ok_and(|comm| comm.trim() == name || comm.trim() == "sudo" || comm.trim() == "env")
}

/// The cluster in `dir`; stopped when dropped, whatever happened.
struct Cluster {
    dir: PathBuf,
    stopped: bool,
}

impl Cluster {
    fn start(dir: PathBuf) -> Cluster {
        let ran = run(
            Command::new("bash")
                .arg(Path::new(ROOT).join("scripts/slurm/start-cluster.sh"))
                .arg(&dir),
            "start-cluster.sh",
            Duration::from_secs(150),
        );
        let cluster = Cluster {
            dir,
            stopped: false,
        };
        assert!(
            ran.ok,
            "the one-node Slurm cluster did not start, so the cluster render cannot be tested \
             (it needs root or password-less sudo and the Debian packages slurm-wlm and munge, \
             which scripts/install-deps.sh installs): {}",
            ran.stderr.trim()
        );
        cluster
    }

    fn conf(&self) -> PathBuf {
        self.dir.join("slurm.conf")
    }

    /// Stops the daemons; returns those still running after the stop script.
    fn stop(&mut self) -> Vec<(String, u32)> {
        self.stopped = true;
        let daemons = daemons(&self.dir);
        let ran = run(
            Command::new("bash")
                .arg(Path::new(ROOT).join("scripts/slurm/stop-cluster.sh"))
                .arg(&self.dir),
            "stop-cluster.sh",
            Duration::from_secs(60),
        );
        if !ran.ok {
            eprintln!("stop-cluster.sh: {}", ran.stderr);
        }
        daemons
            .into_iter()
            .filter(|(name, pid)| alive(name, *pid))
            .collect()
    }

    /// The tail of the daemons' logs and the jobs' outputs, for a failure message.
    fn logs(&self, jobs_dir: &Path) -> String {
        let mut text = String::new();
        let mut files: Vec<PathBuf> = ["slurmctld.log", "slurmd.log"]
            .iter()
            .map(|f| self.dir.join(f))
            .collect();
        for dir in [jobs_dir.join("merged.exr.parts"), jobs_dir.to_path_buf()] {
            if let Ok(entries) = std::fs::read_dir(dir) {
                files.extend(
                    entries
                        .filter_map(|e| e.ok().map(|e| e.path()))
                        .filter(|p| p.extension().is_some_and(|e| e == "out")),
                );
            }
        }
        for f in files {
            let body = std::fs::read_to_string(&f).unwrap_or_default();
            let lines: Vec<&str> = body.lines().collect();
            let tail = lines[lines.len().saturating_sub(12)..].join("\n");
            text += &format!("\n---- {}\n{tail}", f.display());
        }
        text
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        if !self.stopped {
            let left = self.stop();
            if !left.is_empty() {
                eprintln!("cluster daemons still running after the stop: {left:?}");
            }
        }
    }
}

fn linear_bits(path: &Path) -> Vec<[u32; 3]> {
    match read_stamped(path).unwrap_or_else(|e| panic!("{e}")).pixels {
        Pixels::Linear(px) => px
            .iter()
            .map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
            .collect(),
        Pixels::Srgb8(_) => panic!("{} is not an EXR", path.display()),
    }
}

#[test]
fn four_tiles_through_slurm_equal_the_local_render_bit_for_bit() {
    let started = Instant::now();
    let work = tempfile::tempdir().expect("temp dir");
    let w = work.path();
    let mut cluster = Cluster::start(w.join("cluster"));
    let slurm = |program: &str| {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", cluster.conf())
            .env("RAYTREE", RAYTREE)
            .current_dir(w);
        c
    };

    // The tiles and their merge (a dependency on the array, not a sleep).
    let merged = w.join("merged.exr");
    let submit = run(
        slurm("bash")
            .arg(Path::new(ROOT).join("scripts/slurm/submit-tiles.sh"))
            .args(["4", "quiz"])
            .arg(&merged)
            .args(RENDER),
        "submit-tiles.sh",
        Duration::from_secs(60),
    );
    assert!(submit.ok, "submit-tiles.sh failed: {}", submit.stderr);
    assert!(
        submit.stdout.starts_with("tiles=") && submit.stdout.contains(" merge="),
        "submit-tiles.sh prints the job ids: {}",
        submit.stdout
    );
    // A turntable of 4 frames, 2 a task.
    let frames = run(
        slurm("sbatch")
            .args(["--parsable", "--array=0-1", "--output"])
            .arg(w.join("frames-%A_%a.out"))
            .arg(Path::new(ROOT).join("scripts/slurm/render-frames.sbatch"))
            .args(["default", "4", "2"])
            .arg(w.join("spin"))
            .args(["--width", "64", "--height", "48"]),
        "sbatch render-frames.sbatch",
        Duration::from_secs(60),
    );
    assert!(frames.ok, "sbatch of the frames failed: {}", frames.stderr);

    // Wait until the queue is empty (every job done, failed or cancelled).
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let q = run(
            slurm("squeue").args(["-h", "-o", "%i %T %r"]),
            "squeue",
            Duration::from_secs(30),
        );
        if q.ok && q.stdout.trim().is_empty() {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the Slurm jobs did not finish within 300 s; queue: {} {}{}",
            q.stdout.trim(),
            q.stderr.trim(),
            cluster.logs(w)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    assert!(
        merged.exists(),
        "the merge job wrote no {}: a tile or the merge failed{}",
        merged.display(),
        cluster.logs(w)
    );

    // The same render on this machine, in one piece.
    let local = w.join("local.exr");
    let ran = run(
        Command::new(RAYTREE)
            .args(["render", "quiz", "-q"])
            .args(RENDER)
            .arg("-o")
            .arg(&local),
        "raytree render",
        Duration::from_secs(120),
    );
    assert!(ran.ok, "local render failed: {}", ran.stderr);
    let (a, b) = (linear_bits(&merged), linear_bits(&local));
    assert_eq!(a.len(), 160 * 120);
    assert!(a == b, "the Slurm render differs from the local render");
    assert!(
        a.iter().filter(|p| **p != [0; 3]).count() > 1000,
        "the image shows the scene"
    );
    // Every frame, each equal to the same frame rendered here.
    for i in 0..4 {
        let name = format!("frame_{i:04}.png");
        let remote = w.join("spin").join(&name);
        assert!(
            remote.exists(),
            "the frames job wrote no {name}{}",
            cluster.logs(w)
        );
        let here = w.join("local_{frame}.png");
        let ran = run(
            Command::new(RAYTREE)
                .args(["render", "default", "-q", "--width", "64", "--height", "48"])
                .args(["--turntable", "4", "--frame", &i.to_string(), "-o"])
                .arg(&here),
            "raytree render",
            Duration::from_secs(60),
        );
        assert!(ran.ok, "local frame render failed: {}", ran.stderr);
        let here = w.join(format!("local_{i:04}.png"));
        assert!(
            std::fs::read(&remote).expect("remote") == std::fs::read(&here).expect("local"),
            "frame {i} from Slurm differs from the local frame"
        );
    }

    let left = cluster.stop();
    assert!(left.is_empty(), "daemons left running: {left:?}");
    eprintln!(
        "cluster test: {:.1} s from start to teardown",
        started.elapsed().as_secs_f64()
    );
}
