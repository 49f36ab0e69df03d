//! Rendering an image: settings with presets, tiles traced by a rayon pool, a linear `f32` film
//! that accumulates samples in a fixed order per pixel (so the result never depends on the
//! thread count or the tile order), and statistics.

pub mod region;
pub mod session;
pub mod stats;
mod sums;

use std::ops::Range;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::scene::budget::{MemoryError, batch_memory_estimate, memory_limit};
use crate::scene::{CameraFrame, primary_ray, primary_rays};
use crate::trace::{
    NoRecord, PacketScratch, RayCounts, RayKind, SampleInfo, TraceSettings, Tracer,
};
pub use stats::{MemoryStats, RenderStats, RunReport, peak_memory_bytes};
use sums::SumsBuffer;

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
/// the running sums in `sums` (row-major within the rect). Returns the rays traced. Camera
/// rays go in packets ([`accumulate_tile`]).
pub fn trace_tile(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    samples: Range<u32>,
    sums: &mut [Vec3],
) -> RayCounts {
    let mut counts = RayCounts::default();
    accumulate_tile(tracer, frame, rect, samples, sums, &mut counts, None);
    counts
}

/// [`trace_tile`] with every ray traced alone, no packets: the reference the packet path is
/// tested against (bit for bit) and measured against. Use it with [`render_with`].
pub fn trace_tile_single(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    samples: Range<u32>,
    sums: &mut [Vec3],
) -> RayCounts {
    let mut counts = RayCounts::default();
    accumulate_tile_single(tracer, frame, rect, samples, sums, &mut counts, None);
    counts
}

/// Width and height in pixels of the block of neighbouring camera rays traced as one packet
/// ([`Tracer::trace_packet`]): 32 rays, the most a packet's `u32` lane masks hold (1.2 % fewer
/// instructions than 4×4 on the bench's camera- and shadow-ray frame).
pub const PACKET_BLOCK: (u32, u32) = (8, 4);
const PACKET_RAYS: usize = (PACKET_BLOCK.0 * PACKET_BLOCK.1) as usize;

/// The one tile loop of the batch render ([`trace_tile`]) and the viewer's session: adds
/// samples `samples` of every pixel of `rect` to its running sum in `sums` (row-major within
/// the rect), each pixel's samples in index order, so a pixel's sum never depends on how the
/// samples were split into passes. Rays traced are added to `counts`; when `samples` holds
/// sample 0, each pixel's [`SampleInfo`] of that sample is appended to `first` (row-major),
/// for the viewer's image modes.
///
/// The camera rays of each [`PACKET_BLOCK`] of pixels are traced together, sample by sample
/// (their closest hits one packet query, their shadow rays towards each light another); the
/// colours and facts are those of [`accumulate_tile_single`] bit for bit.
///
/// Where the traversals use AVX2 ([`crate::accel::packet_uses_avx2`]), the whole tile loop,
/// the packets' hit set-up and shading included, is compiled for x86-64-v3 (`pulp`): the same
/// SSE arithmetic VEX-encoded, with no fused multiply-add formed (Rust never contracts), so
/// every number is the baseline build's, in 4 % fewer instructions (the `--opaque` 80k
/// bench frame). `tests/packets.rs` holds it to the single-ray path, which stays baseline.
pub fn accumulate_tile(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    samples: Range<u32>,
    sums: &mut [Vec3],
    counts: &mut RayCounts,
    first: Option<&mut Vec<SampleInfo>>,
) {
    let tile = Tile(tracer, frame, rect, samples, sums, counts, first);
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = crate::accel::avx2() {
        return v3.vectorize(TileAvx2(tile));
    }
    tile.accumulate();
}

/// The arguments of [`accumulate_tile`], in its order; its body is [`Tile::accumulate`].
struct Tile<'a>(
    &'a Tracer,
    &'a CameraFrame,
    Rect,
    Range<u32>,
    &'a mut [Vec3],
    &'a mut RayCounts,
    Option<&'a mut Vec<SampleInfo>>,
);

/// [`Tile::accumulate`] as the function `pulp` compiles with AVX2: its `call` must be inlined
/// there (a closure would not take the target features), hence a type.
#[cfg(target_arch = "x86_64")]
struct TileAvx2<'a>(Tile<'a>);

#[cfg(target_arch = "x86_64")]
impl pulp::NullaryFnOnce for TileAvx2<'_> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        self.0.accumulate();
    }
}

impl Tile<'_> {
    /// The body of [`accumulate_tile`], inlined into the build it runs in.
    #[inline(always)]
    fn accumulate(self) {
        let Tile(tracer, frame, rect, samples, sums, counts, first) = self;
        let (bw, bh) = PACKET_BLOCK;
        let base = first.as_ref().map_or(0, |f| f.len());
        let mut first = first.filter(|_| samples.contains(&0));
        if let Some(f) = first.as_mut() {
            f.resize(
                base + (rect.width * rect.height) as usize,
                SampleInfo::default(),
            );
        }
        let mut rays = [crate::geometry::Ray::new(Vec3::ZERO, Vec3::Z); PACKET_RAYS];
        let mut out = [(Vec3::ZERO, SampleInfo::default()); PACKET_RAYS];
        let mut scratch = PacketScratch::take();
        for by in (0..rect.height).step_by(bh as usize) {
            for bx in (0..rect.width).step_by(bw as usize) {
                // The block's pixels inside the rect, row-major: (index in `sums`, x, y).
                let mut pixels = [(0usize, 0u32, 0u32); PACKET_RAYS];
                // Their image positions alone, lane by lane, for the camera rays.
                let mut xy = [(0u32, 0u32); PACKET_RAYS];
                let mut n = 0;
                for j in by..(by + bh).min(rect.height) {
                    for i in bx..(bx + bw).min(rect.width) {
                        pixels[n] = ((j * rect.width + i) as usize, rect.x + i, rect.y + j);
                        xy[n] = (rect.x + i, rect.y + j);
                        n += 1;
                    }
                }
                // The low `n` bits (`n` is 1 to 32: a shift by 32 would not be defined).
                let active = u32::MAX >> (32 - n);
                for s in samples.clone() {
                    primary_rays(frame, &xy, n, s, &mut rays);
                    tracer.trace_packet(&rays, active, counts, &mut out, &mut *scratch);
                    for (&(at, _, _), &(c, info)) in pixels[..n].iter().zip(&out[..n]) {
                        sums[at] += c;
                        if s == 0
                            && let Some(first) = first.as_mut()
                        {
                            first[base + at] = info;
                        }
                    }
                }
            }
        }
        PacketScratch::keep(scratch);
    }
}

/// [`accumulate_tile`] with every ray traced alone: one pixel after another, each pixel's
/// samples in index order.
pub fn accumulate_tile_single(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    samples: Range<u32>,
    sums: &mut [Vec3],
    counts: &mut RayCounts,
    mut first: Option<&mut Vec<SampleInfo>>,
) {
    for j in 0..rect.height {
        for i in 0..rect.width {
            let (x, y) = (rect.x + i, rect.y + j);
            let sum = &mut sums[(j * rect.width + i) as usize];
            for s in samples.clone() {
                let (c, info) = trace_sample(tracer, frame, x, y, s, counts);
                *sum += c;
                if s == 0
                    && let Some(first) = first.as_mut()
                {
                    first.push(info);
                }
            }
        }
    }
}

/// The viewer's coarse preview of `rect` (inside a `width × height` image): sample 0 of the
/// pixel at the centre of each `block × block` block (clamped to the image), copied to the
/// whole block; the colours and the facts, row-major within the rect, with the rays traced
/// added to `counts`. The centres of neighbouring blocks are traced as packets of
/// [`PACKET_BLOCK`] blocks ([`Tracer::trace_packet`]), bit for bit as
/// [`preview_tile_single`] traces them one by one.
pub fn preview_tile(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    block: u32,
    counts: &mut RayCounts,
) -> (Vec<Vec3>, Vec<SampleInfo>) {
    preview_with(frame, rect, block, |centres, out| {
        let mut rays = [crate::geometry::Ray::new(Vec3::ZERO, Vec3::Z); PACKET_RAYS];
        let mut traced = [(Vec3::ZERO, SampleInfo::default()); PACKET_RAYS];
        let mut scratch = PacketScratch::take();
        for (chunk, outs) in centres.chunks(PACKET_RAYS).zip(out.chunks_mut(PACKET_RAYS)) {
            for (ray, &(x, y)) in rays.iter_mut().zip(chunk) {
                *ray = primary_ray(frame, x, y, 0);
            }
            let active = u32::MAX >> (32 - chunk.len());
            tracer.trace_packet(&rays, active, counts, &mut traced, &mut scratch);
            outs.copy_from_slice(&traced[..chunk.len()]);
        }
        PacketScratch::keep(scratch);
    })
}

/// [`preview_tile`] with every ray traced alone: the reference it is tested against.
pub fn preview_tile_single(
    tracer: &Tracer,
    frame: &CameraFrame,
    rect: Rect,
    block: u32,
    counts: &mut RayCounts,
) -> (Vec<Vec3>, Vec<SampleInfo>) {
    preview_with(frame, rect, block, |centres, out| {
        for (o, &(x, y)) in out.iter_mut().zip(centres) {
            *o = trace_sample(tracer, frame, x, y, 0, counts);
        }
    })
}

/// The block centres of a preview of `rect` (clamped to the frame's image), in packets of
/// [`PACKET_BLOCK`] blocks (block rows and columns), traced by `trace` (centres in, sample
/// colour and facts out), copied to their blocks.
fn preview_with(
    frame: &CameraFrame,
    rect: Rect,
    block: u32,
    trace: impl FnOnce(&[(u32, u32)], &mut [(Vec3, SampleInfo)]),
) -> (Vec<Vec3>, Vec<SampleInfo>) {
    let block = block.max(1);
    let (w, h) = frame.size();
    let (cols, rows) = (rect.width.div_ceil(block), rect.height.div_ceil(block));
    let (bw, bh) = PACKET_BLOCK;
    // Block coordinates in packet order, and their centres in image coordinates.
    let mut blocks = Vec::with_capacity((cols * rows) as usize);
    for py in (0..rows).step_by(bh as usize) {
        for px in (0..cols).step_by(bw as usize) {
            for j in py..(py + bh).min(rows) {
                for i in px..(px + bw).min(cols) {
                    blocks.push((i, j));
                }
            }
        }
    }
    let centres: Vec<(u32, u32)> = blocks
        .iter()
        .map(|&(i, j)| {
            (
                (rect.x + i * block + block / 2).min(w.saturating_sub(1)),
                (rect.y + j * block + block / 2).min(h.saturating_sub(1)),
            )
        })
        .collect();
    let mut traced = vec![(Vec3::ZERO, SampleInfo::default()); centres.len()];
    trace(&centres, &mut traced);
    let n = (rect.width * rect.height) as usize;
    let mut pixels = vec![Vec3::ZERO; n];
    let mut facts = vec![SampleInfo::default(); n];
    for (&(i, j), &(c, info)) in blocks.iter().zip(&traced) {
        for y in j * block..((j + 1) * block).min(rect.height) {
            for x in i * block..((i + 1) * block).min(rect.width) {
                pixels[(y * rect.width + x) as usize] = c;
                facts[(y * rect.width + x) as usize] = info;
            }
        }
    }
    (pixels, facts)
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
    let ray = primary_ray(frame, x, y, s);
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
    render_part_with(
        tracer,
        region::full(width, height),
        samples,
        threads,
        progress,
        tile,
    )
}

/// [`render_with`] of the pixels of `region` only (inside the tracer's `[render]` size): an
/// image of the region's size whose pixels equal, bit for bit, the same pixels of the full
/// image, as the camera frame is the full image's and each pixel's samples are keyed by its
/// coordinates in it. `progress` gets (pixels done, pixels in the region); the statistics'
/// width and height are the region's.
pub(crate) fn render_part_with(
    tracer: &Tracer,
    region: Rect,
    samples: u32,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
    tile: &TileFn<'_>,
) -> Result<(Image, RenderStats), RenderError> {
    let (width, height) = (tracer.scene.render.width, tracer.scene.render.height);
    let what = if region == region::full(width, height) {
        format!("a {width}x{height} render")
    } else {
        format!(
            "a {}x{} region of a {width}x{height} render",
            region.width, region.height
        )
    };
    memory_limit().check(what, batch_memory_estimate(region.width, region.height))?;
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
    // The region's tiles, in the full image's coordinates.
    let tiles: Vec<Rect> = tiles(region.width, region.height, TILE_SIZE)
        .into_iter()
        .map(|r| Rect {
            x: region.x + r.x,
            y: region.y + r.y,
            ..r
        })
        .collect();
    let total = region.width as u64 * region.height as u64;
    let start = Instant::now();
    // One buffer for every tile's sums, tile after tile: no allocation per tile; the last
    // render's when there was one. Taken inside the timed part, so a fresh buffer's page
    // faults count; either kind is zeroed tile by tile by the workers, in parallel (a fresh
    // one's pages are faulted in there, not by this thread before the first tile starts).
    let mut sums = SumsBuffer::take(tracer, total as usize);
    let mut parts: Vec<&mut [Vec3]> = Vec::with_capacity(tiles.len());
    let mut rest: &mut [Vec3] = sums.vec3s_mut(total as usize);
    for rect in &tiles {
        let (part, tail) = rest.split_at_mut((rect.width * rect.height) as usize);
        parts.push(part);
        rest = tail;
    }
    let done = AtomicU64::new(0);
    let work = || -> Vec<Result<RayCounts, RenderError>> {
        // One task per tile, so neither worker is left waiting while the other runs a long
        // unsplit piece (see the viewer's `Job::pass`).
        tiles
            .par_iter()
            .zip(parts.into_par_iter())
            .with_max_len(1)
            .map(|(&rect, sums)| {
                sums.fill(Vec3::ZERO);
                let outcome = catch_unwind(AssertUnwindSafe(|| {
                    tile(tracer, &frame, rect, 0..samples, sums)
                }));
                let n = rect.width as u64 * rect.height as u64;
                progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
                outcome.map_err(|panic| RenderError::WorkerPanicked {
                    x: rect.x,
                    y: rect.y,
                    message: panic_message(panic.as_ref()),
                })
            })
            .collect()
    };
    let (results, used_threads) = match &own_pool {
        Some(pool) => (pool.install(work), pool.current_num_threads()),
        None => (work(), rayon::current_num_threads()),
    };
    let render_secs = start.elapsed().as_secs_f64();
    let mut image = Image::new(region.width, region.height);
    let mut rays = RayCounts::default();
    let mut offset = 0;
    let all: &[Vec3] = sums.vec3s_mut(total as usize);
    for (rect, result) in tiles.iter().zip(results) {
        rays.add(&result?);
        let tile_sums = &all[offset..offset + (rect.width * rect.height) as usize];
        offset += tile_sums.len();
        for j in 0..rect.height {
            for i in 0..rect.width {
                let sum = tile_sums[(j * rect.width + i) as usize];
                let at = (rect.y - region.y + j) * region.width + rect.x - region.x + i;
                image.pixels[at as usize] = sum / samples as f32;
            }
        }
    }
    sums.keep(tracer);
    let stats = RenderStats {
        width: region.width,
        height: region.height,
        samples,
        threads: used_threads,
        accel: Some(tracer.accel.kind()),
        rays,
        build_secs: tracer.build_secs,
        render_secs,
    };
    Ok((image, stats))
}

/// The message a caught panic carries: `panic!` with a literal gives a `&str`, with a format
/// a `String`; anything else (`panic_any`) has no text to show.
pub(crate) fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panic_messages_of_str_string_and_other_payloads() {
        let caught = |f: fn()| {
            let payload = catch_unwind(f).expect_err("f panics");
            panic_message(payload.as_ref())
        };
        assert_eq!(caught(|| panic!("literal")), "literal");
        assert_eq!(caught(|| panic!("formatted {}", 7)), "formatted 7");
        assert_eq!(caught(|| std::panic::panic_any(7_u8)), "unknown panic");
    }

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
}
