//! Rendering an image: settings with presets, tiles traced by a rayon pool, a linear `f32` film
//! that accumulates samples in a fixed order per pixel (so the result never depends on the
//! thread count or the tile order), and statistics.

pub mod camera;
pub mod sampling;
pub mod session;

use std::ops::Range;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::trace::{NoRecord, RayCounts, RayKind, SampleInfo, TraceSettings, Tracer};
pub use camera::CameraFrame;
pub use sampling::sample_offset;

/// Side of a square tile in pixels.
pub const TILE_SIZE: u32 = 32;

/// How to render, beyond the scene's own `[render]` section.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RenderSettings {
    pub trace: TraceSettings,
    /// Worker threads; 0 uses every core.
    pub threads: usize,
}

/// A linear RGB image, row-major, y = 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }
}

/// A rectangle of pixels: `x..x+width`, `y..y+height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The tiles covering a `width × height` image, nearest the centre first.
pub fn tiles(width: u32, height: u32, size: u32) -> Vec<Rect> {
    let mut out = Vec::new();
    for y in (0..height).step_by(size as usize) {
        for x in (0..width).step_by(size as usize) {
            out.push(Rect {
                x,
                y,
                width: size.min(width - x),
                height: size.min(height - y),
            });
        }
    }
    let (cx, cy) = (width as f32 * 0.5, height as f32 * 0.5);
    let dist = |r: &Rect| {
        let dx = r.x as f32 + r.width as f32 * 0.5 - cx;
        let dy = r.y as f32 + r.height as f32 * 0.5 - cy;
        dx * dx + dy * dy
    };
    out.sort_by(|a, b| {
        dist(a)
            .total_cmp(&dist(b))
            .then((a.y, a.x).cmp(&(b.y, b.x)))
    });
    out
}

/// Traces samples `samples` of every pixel of `rect`, adding each sample, in index order, to
/// the running sums in `sums` (row-major within the rect). Returns the rays traced.
pub fn trace_tile(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    samples: Range<u32>,
    sums: &mut [Vec3],
) -> RayCounts {
    let mut counts = RayCounts::default();
    for j in 0..rect.height {
        for i in 0..rect.width {
            let (x, y) = (rect.x + i, rect.y + j);
            let sum = &mut sums[(j * rect.width + i) as usize];
            for s in samples.clone() {
                *sum += trace_sample(tracer, frame, x, y, s, &mut counts).0;
            }
        }
    }
    counts
}

/// Sample `s` of pixel (`x`, `y`): its colour and the facts the image modes show.
pub fn trace_sample(
    tracer: &Tracer,
    frame: &CameraFrame,
    x: u32,
    y: u32,
    s: u32,
    counts: &mut RayCounts,
) -> (Vec3, SampleInfo) {
    let (u, v) = sample_offset(x, y, s);
    let ray = frame.ray(x as f32 + u, y as f32 + v);
    let mut info = SampleInfo::default();
    let c = tracer.trace(
        &ray,
        RayKind::Primary,
        0,
        Vec3::ONE,
        counts,
        &mut info,
        &mut NoRecord,
    );
    (c, info)
}

// The figures of a render (time, rays, memory) live in `stats`; [`render`] returns them, so
// they are re-exported beside it.
pub mod stats;
pub use stats::{MemoryStats, RenderStats, peak_memory_bytes};

/// A render that could not complete.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("a render worker failed on the tile at ({x}, {y}): {message}")]
    WorkerPanicked { x: u32, y: u32, message: String },
    #[error("cannot start {threads} render threads: {message}")]
    Threads { threads: usize, message: String },
    /// Refused before allocating: the image would not fit the memory budget.
    #[error(transparent)]
    TooLarge(#[from] MemoryError),
}

// The memory budget (SPEC §9): sizes a file may ask for are checked against an estimate of the
// memory they need before anything of that size is allocated, so a hostile or mistyped scene
// gets a sentence instead of an out-of-memory kill.

/// Peak bytes per pixel of [`render`] and an export: the tile sums of every tile held until the
/// image is assembled (12), the image (12), and the encoder's copy (3 for PNG, about 12 for EXR
/// written to memory first), rounded up.
pub const BATCH_BYTES_PER_PIXEL: u64 = 40;

/// Bytes per pixel of the viewer: the session's running sums (12), the film (12), the image-mode
/// facts (24), the display buffer (16), the GPU texture (16) and tiles in flight, rounded up.
pub const VIEWER_BYTES_PER_PIXEL: u64 = 96;

/// Peak bytes per triangle while an OBJ is read and accelerated: tobj's face list (up to 104
/// bytes a face, doubled by vector growth), its index map and index list, the scene's triangle
/// (44), the accelerator's copy and the BVH build. Measured: a 1M-triangle OBJ of random
/// triangles peaks at about 410 bytes per triangle (`/usr/bin/time -v raytree render`).
pub const TRIANGLE_BYTES: u64 = 450;

/// Bytes per OBJ vertex while reading (tobj's position list and the mesh's copy), rounded up.
pub const VERTEX_BYTES: u64 = 32;

/// The budget used when the machine's memory is unknown.
pub const FALLBACK_MEMORY_LIMIT: u64 = 16 << 30;

/// How much memory a render or a load may plan to use, and where that number came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryLimit {
    pub bytes: u64,
    /// "three quarters of this machine's 24.0 GiB", "RAYTREE_MEMORY_LIMIT=512", ...
    pub source: String,
}

impl MemoryLimit {
    /// Refuses `estimate` bytes for `what` ("a 16384x16384 render") when over the limit.
    pub fn check(&self, what: impl Into<String>, estimate: u64) -> Result<(), MemoryError> {
        if estimate <= self.bytes {
            return Ok(());
        }
        Err(MemoryError {
            what: what.into(),
            estimate,
            limit: self.clone(),
        })
    }
}

/// Something refused because its memory estimate is over the limit: one sentence.
#[derive(Clone, Debug, thiserror::Error)]
#[error(
    "{what} would need about {}, more than the memory limit of {} ({})",
    format_bytes(*estimate),
    format_bytes(limit.bytes),
    limit.source
)]
pub struct MemoryError {
    pub what: String,
    pub estimate: u64,
    pub limit: MemoryLimit,
}

/// The memory budget: `RAYTREE_MEMORY_LIMIT` (a whole number of MiB) if set, else three
/// quarters of the machine's memory (Linux `/proc/meminfo`), else 16 GiB. Read once.
pub fn memory_limit() -> MemoryLimit {
    static LIMIT: std::sync::OnceLock<MemoryLimit> = std::sync::OnceLock::new();
    LIMIT
        .get_or_init(|| {
            memory_limit_from(std::env::var("RAYTREE_MEMORY_LIMIT").ok(), machine_memory())
        })
        .clone()
}

/// [`memory_limit`] from its inputs: the variable's value and the machine's memory in bytes.
pub fn memory_limit_from(variable: Option<String>, machine: Option<u64>) -> MemoryLimit {
    const HOW: &str = "set RAYTREE_MEMORY_LIMIT to a number of MiB to change it";
    let default = || match machine {
        Some(total) => MemoryLimit {
            bytes: total / 4 * 3,
            source: format!(
                "three quarters of this machine's {}; {HOW}",
                format_bytes(total)
            ),
        },
        None => MemoryLimit {
            bytes: FALLBACK_MEMORY_LIMIT,
            source: format!("the default, as this machine's memory is unknown; {HOW}"),
        },
    };
    match variable {
        None => default(),
        Some(text) => match text.trim().parse::<u64>() {
            Ok(mib) if mib > 0 => MemoryLimit {
                bytes: mib.saturating_mul(1 << 20),
                source: format!("set by RAYTREE_MEMORY_LIMIT={mib}"),
            },
            // A typo must not silently lift or lower the limit: say that it was ignored.
            _ => {
                let mut limit = default();
                limit.source = format!(
                    "{}; RAYTREE_MEMORY_LIMIT=\"{}\" is not a whole number of MiB and was ignored",
                    limit.source.split(';').next().unwrap_or_default(),
                    text.escape_debug()
                );
                limit
            }
        },
    }
}

/// Total memory from `/proc/meminfo` (Linux), in bytes.
fn machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Peak memory of a `width × height` batch render and its export.
pub fn batch_memory_estimate(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * BATCH_BYTES_PER_PIXEL
}

/// Memory of the viewer's buffers for a `width × height` image.
pub fn viewer_memory_estimate(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * VIEWER_BYTES_PER_PIXEL
}

/// Peak memory of reading an OBJ of `text_bytes` with `vertices` vertices and `triangles`
/// triangles (after triangulation) and accelerating it.
pub fn mesh_memory_estimate(text_bytes: u64, vertices: u64, triangles: u64) -> u64 {
    text_bytes
        .saturating_add(vertices.saturating_mul(VERTEX_BYTES))
        .saturating_add(triangles.saturating_mul(TRIANGLE_BYTES))
}

/// `1.5 GiB`, `12.0 MiB`, `512 bytes`.
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if bytes >= size {
            return format!("{:.1} {unit}", bytes as f64 / size as f64);
        }
    }
    format!("{bytes} bytes")
}

/// Renders the tracer's scene at its `[render]` size with `samples` samples per pixel on
/// `threads` threads (0: all cores). `progress` is called with (pixels done, pixels in all)
/// after every tile, from worker threads.
pub fn render(
    tracer: &Tracer,
    samples: u32,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Image, RenderStats), RenderError> {
    render_with(tracer, samples, threads, progress, &trace_tile)
}

/// The work of one tile, as [`trace_tile`] does it.
pub type TileFn<'a> =
    dyn Fn(&Tracer, &CameraFrame, Rect, Range<u32>, &mut [Vec3]) -> RayCounts + Sync + 'a;

/// [`render`] with each tile traced by `tile` instead of [`trace_tile`]: the fault tests use it
/// to make a worker panic and check that the panic is caught and reported, not lost.
pub fn render_with(
    tracer: &Tracer,
    samples: u32,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
    tile: &TileFn<'_>,
) -> Result<(Image, RenderStats), RenderError> {
    let (width, height) = (tracer.scene.render.width, tracer.scene.render.height);
    memory_limit().check(
        format!("a {width}x{height} render"),
        batch_memory_estimate(width, height),
    )?;
    let frame = CameraFrame::new(&tracer.scene.camera, width, height);
    // The pool we are on (rayon's global one, which the CLI sizes by `--threads`) when it has
    // the size asked for; a pool of our own otherwise.
    let own_pool = if threads == 0 || threads == rayon::current_num_threads() {
        None
    } else {
        Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| RenderError::Threads {
                    threads,
                    message: e.to_string(),
                })?,
        )
    };
    let tiles = tiles(width, height, TILE_SIZE);
    let total = width as u64 * height as u64;
    // One buffer for every tile's sums, tile after tile: no allocation per tile.
    let mut sums = vec![Vec3::ZERO; total as usize];
    let mut parts: Vec<&mut [Vec3]> = Vec::with_capacity(tiles.len());
    let mut rest = sums.as_mut_slice();
    for rect in &tiles {
        let (part, tail) = rest.split_at_mut((rect.width * rect.height) as usize);
        parts.push(part);
        rest = tail;
    }
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let work = || -> Vec<Result<RayCounts, RenderError>> {
        tiles
            .par_iter()
            .zip(parts.into_par_iter())
            .map(|(&rect, sums)| {
                let outcome = catch_unwind(AssertUnwindSafe(|| {
                    tile(tracer, &frame, rect, 0..samples, sums)
                }));
                let n = rect.width as u64 * rect.height as u64;
                progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
                outcome.map_err(|panic| {
                    let message = panic
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| panic.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "unknown panic".into());
                    RenderError::WorkerPanicked {
                        x: rect.x,
                        y: rect.y,
                        message,
                    }
                })
            })
            .collect()
    };
    let (results, used_threads) = match &own_pool {
        Some(pool) => (pool.install(work), pool.current_num_threads()),
        None => (work(), rayon::current_num_threads()),
    };
    let render_secs = start.elapsed().as_secs_f64();
    let mut image = Image::new(width, height);
    let mut rays = RayCounts::default();
    let mut offset = 0;
    for (rect, result) in tiles.iter().zip(results) {
        rays.add(&result?);
        let tile_sums = &sums[offset..offset + (rect.width * rect.height) as usize];
        offset += tile_sums.len();
        for j in 0..rect.height {
            for i in 0..rect.width {
                let sum = tile_sums[(j * rect.width + i) as usize];
                image.pixels[((rect.y + j) * width + rect.x + i) as usize] = sum / samples as f32;
            }
        }
    }
    let stats = RenderStats {
        width,
        height,
        samples,
        threads: used_threads,
        accel: Some(tracer.accel.kind()),
        rays,
        build_secs: tracer.build_secs,
        render_secs,
    };
    Ok((image, stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_image_once() {
        let (w, h) = (100, 70);
        let mut seen = vec![0u8; (w * h) as usize];
        for r in tiles(w, h, 32) {
            for y in r.y..r.y + r.height {
                for x in r.x..r.x + r.width {
                    seen[(y * w + x) as usize] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        let first = tiles(w, h, 32)[0];
        assert!(first.x <= 50 && 50 < first.x + first.width + 32);
    }

    #[test]
    fn memory_limit_comes_from_the_variable_or_the_machine() {
        let l = memory_limit_from(Some("512".into()), Some(8 << 30));
        assert_eq!(
            (l.bytes, l.source.as_str()),
            (512 << 20, "set by RAYTREE_MEMORY_LIMIT=512")
        );
        let l = memory_limit_from(None, Some(8 << 30));
        assert_eq!(l.bytes, 6 << 30);
        assert_eq!(
            l.source,
            "three quarters of this machine's 8.0 GiB; set RAYTREE_MEMORY_LIMIT to a number of \
             MiB to change it"
        );
        let l = memory_limit_from(Some("lots".into()), None);
        assert_eq!(l.bytes, FALLBACK_MEMORY_LIMIT);
        assert!(
            l.source.contains("\"lots\" is not a whole number of MiB"),
            "{}",
            l.source
        );
        assert!(
            l.check("a render", batch_memory_estimate(16384, 16384))
                .is_ok()
        );
        let l = memory_limit_from(Some("1024".into()), None);
        let e = l
            .check("a 16384x16384 render", batch_memory_estimate(16384, 16384))
            .expect_err("10 GiB is over 1 GiB")
            .to_string();
        assert_eq!(
            e,
            "a 16384x16384 render would need about 10.0 GiB, more than the memory limit of \
             1.0 GiB (set by RAYTREE_MEMORY_LIMIT=1024)"
        );
    }
}
