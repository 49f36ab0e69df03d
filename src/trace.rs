//! THE recursive trace of the lecture's pseudocode (SPEC §1), generic over a [`Recorder`]: tiles
//! use [`NoRecord`], whose calls compile away; a clicked pixel uses the tree recorder of
//! [`crate::ray_tree`], so the tree and the image can never disagree.
//!
//! ```text
//! trace(p, d, step):
//!     if step > max_depth            return background        (termination: maximum depth)
//!     hit = intersect(p, d)
//!     if hit is a light              return the light's colour (termination: light source)
//!     if no hit                      return background        (termination: no intersection)
//!     local = ambient + Σ_lights shadow-ray visibility · (diffuse + specular)
//!     return local + kr·trace(q, R, step+1) + kt·trace(q, T, step+1)
//! ```

use std::sync::Arc;

use glam::{Vec2, Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::accel::{Accel, AccelKind, PrimHit, PrimSet, Visits};
use crate::geometry::{
    Methods, Ray, ShadingNormals, interpolate_normal, intersect_sphere, keep_side,
    offset_ray_origin, sphere_hit_point, terminator_origin, triangle_hit_point,
};
use crate::scene::{MaterialId, ObjectId, Scene};
use crate::shade::{LightTerms, light_terms_with, reflect, refract};

/// Rays (shadow rays included) one sample may trace; past it, branches end as
/// [`EndReason::Budget`]. Natural scenes use a few dozen; the budget bounds the work of
/// pathological ones (a glass ball in a box of mirrors at depth 64 would otherwise trace
/// millions of rays for one pixel) while the tree and the image still agree exactly.
pub const MAX_RAYS_PER_SAMPLE: u32 = 1 << 16;

/// What a ray is, in the tree and in the statistics.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RayKind {
    Primary,
    Reflected,
    Refracted,
    Shadow,
}

/// Why a branch of the tree ended without being shaded (SPEC §5b `end`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndReason {
    /// The ray met nothing: background.
    NoHit,
    /// The ray met a visible light: the light's colour.
    HitLight,
    /// The ray is deeper than `max_depth`: background, without being traced.
    MaxDepth,
    /// The ray's weight fell below the cutoff (adaptive depth): background, without being traced.
    Cutoff,
    /// The sample had traced [`MAX_RAYS_PER_SAMPLE`] rays already: background, without being
    /// traced.
    Budget,
}

// `SampleInfo::ends` holds one bit per reason.
const _: () = assert!((EndReason::Budget as u32) < u8::BITS);

/// Rays traced, by kind. Children past `max_depth`, below the cutoff or past the ray budget are
/// not traced and not counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RayCounts {
    pub primary: u64,
    pub reflected: u64,
    pub refracted: u64,
    pub shadow: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.reflected + self.refracted + self.shadow
    }

    pub fn add(&mut self, other: &RayCounts) {
        self.primary += other.primary;
        self.reflected += other.reflected;
        self.refracted += other.refracted;
        self.shadow += other.shadow;
    }

    fn count(&mut self, kind: RayKind) {
        match kind {
            RayKind::Primary => self.primary += 1,
            RayKind::Reflected => self.reflected += 1,
            RayKind::Refracted => self.refracted += 1,
            RayKind::Shadow => self.shadow += 1,
        }
    }
}

/// Per-sample facts for the image modes: the deepest ray traced, the rays traced (shadow rays
/// included), every way its branches ended, the normal at the primary hit and how far away it
/// is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleInfo {
    pub depth_reached: u32,
    pub rays: u32,
    /// Bit `1 << reason as u8` for each [`EndReason`] met anywhere in the tree.
    pub ends: u8,
    /// Unit normal (turned towards the camera) at the primary hit; zero when it met no surface.
    pub normal: Vec3,
    /// Distance along the primary ray to the surface (or visible light) it met; INFINITY when
    /// it met nothing. The scene view's depth, to dim the rays behind surfaces.
    pub hit_t: f32,
}

impl Default for SampleInfo {
    fn default() -> Self {
        Self {
            depth_reached: 0,
            rays: 0,
            ends: 0,
            normal: Vec3::ZERO,
            hit_t: f32::INFINITY,
        }
    }
}

/// The surface a ray met, as the tree shows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f32,
    pub point: Vec3,
    /// Unit shading normal: the geometric normal, or the one interpolated from the mesh's
    /// vertex normals, on the side of the surface the ray came from (the geometric side).
    pub normal: Vec3,
    /// Unit geometric normal turned towards the incoming ray: decides front/back, entering or
    /// leaving and the ray-origin offset.
    pub geometric_normal: Vec3,
    pub object: ObjectId,
    pub material: MaterialId,
    pub front_face: bool,
    /// Barycentric weights of the triangle's vertices; `None` for spheres.
    pub barycentric: Option<[f32; 3]>,
    /// The triangle's unit vertex normals, turned like `geometric_normal`, when it has them.
    pub vertex_normals: Option<[Vec3; 3]>,
    /// Texture coordinates where the triangle has them and its material a texture.
    pub uv: Option<Vec2>,
    /// The diffuse (`map_Kd`) and ambient (`map_Ka`) texels at `uv`, linear RGB.
    pub texel_kd: Option<Vec3>,
    pub texel_ka: Option<Vec3>,
}

/// One light's shadow ray at a hit, as the tree shows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowTest {
    pub light: usize,
    /// Unit vector from the hit point to the light's centre.
    pub to_light: Vec3,
    pub distance: f32,
    /// The first object on the segment to the light, if any. `None` also when the light is
    /// behind the surface (`N·L ≤ 0`), where no shadow ray is needed.
    pub blocked_by: Option<ObjectId>,
    /// Distance along the shadow ray (from its offset origin) to the blocker.
    pub blocked_at: Option<f32>,
    /// Whether the shadow ray was cast: not when the light is behind the surface (`N·L ≤ 0`)
    /// nor when its unshadowed contribution is exactly zero (see `casts_shadow_ray`).
    pub traced: bool,
    /// The shading normal faces the light but the light is behind the geometric surface and
    /// the smooth surface does not reach above it (STABILITY N3): the light adds nothing, and
    /// no shadow ray is cast.
    pub behind_surface: bool,
    pub terms: LightTerms,
}

/// Receives every step of one trace. All methods default to doing nothing.
pub trait Recorder {
    /// `false` lets the trace skip work done only for the recorder (finding the blocker's name).
    const ENABLED: bool;
    fn enter(&mut self, _kind: RayKind, _depth: u32, _ray: &Ray, _weight: Vec3) {}
    /// The ray just entered had its direction mirrored back across the geometric plane of the
    /// surface it leaves (STABILITY N2).
    fn direction_corrected(&mut self) {}
    fn end(&mut self, _reason: EndReason) {}
    /// The ray ended on visible light `light` at distance `t`.
    fn light(&mut self, _light: usize, _t: f32) {}
    fn hit(&mut self, _hit: &SurfaceHit, _view: Vec3) {}
    fn shadow(&mut self, _test: &ShadowTest) {}
    fn local(&mut self, _ambient: Vec3, _diffuse: Vec3, _specular: Vec3) {}
    fn total_internal_reflection(&mut self) {}
    /// The weights the children get: `kr` (plus `kt` on total internal reflection) and `kt`.
    fn child_weights(&mut self, _reflected: Vec3, _refracted: Vec3) {}
    fn leave(&mut self, _color: Vec3) {}
}

/// The recorder of image tiles: records nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRecord;

impl Recorder for NoRecord {
    const ENABLED: bool = false;
}

/// How to trace, apart from what the scene's `[render]` section says: one flat struct with
/// documented ranges.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceSettings {
    pub accel: AccelKind,
    pub methods: Methods,
    /// Rays whose weight (largest channel of the product of kr/kt along the path) is below
    /// this are not traced ("adaptive depth"). 0 disables it; range 0..1.
    pub cutoff: f32,
}

impl Default for TraceSettings {
    fn default() -> Self {
        Self {
            accel: AccelKind::Auto,
            methods: Methods::default(),
            cutoff: 0.0,
        }
    }
}

/// The spheres and triangles of a scene as the accelerators see them.
pub fn prim_set(scene: &Scene) -> PrimSet {
    PrimSet {
        spheres: scene.spheres.iter().map(|s| (s.center, s.radius)).collect(),
        triangles: scene.triangles.par_iter().map(|t| t.vertices).collect(),
    }
}

/// A scene made ready to trace: the immutable snapshot workers read.
pub struct Tracer {
    pub scene: Arc<Scene>,
    /// Shared, so edits that leave the geometry alone (camera, lights, materials, methods)
    /// reuse it instead of rebuilding.
    pub accel: Arc<Accel>,
    pub settings: TraceSettings,
    /// Lights with a radius, which end the rays that meet them.
    visible_lights: Vec<usize>,
    /// Seconds spent building the accelerator.
    pub build_secs: f64,
    /// The batch render's per-pixel sums, kept from one render to the next so that a repeated
    /// render (`--frames`, a turntable) writes into memory the process has already touched
    /// instead of faulting in fresh pages (see [`Tracer::take_sums`]).
    sums: std::sync::Mutex<Option<SumsBuffer>>,
}

/// Memory for a batch render's per-pixel sums: anonymous pages straight from the kernel,
/// zeroed, with transparent huge pages asked for where the system offers them on request
/// (Linux's default `madvise` mode; Embree asks the same for its large allocations). Only
/// the whole 2 MiB pages inside the mapping can be huge: a 640×480 render's 3.7 MB holds one,
/// so its first frame takes one 2 MiB fault and about 450 of 4 KiB instead of 900 (the
/// bench's `--opaque` 80k first frame, 12 alternating runs: 27.9 → 26.4 ms). Aligning the
/// buffer so that both of its pages are huge was measured no faster (session 18). The warm
/// frames reuse the buffer. The allocator's memory where mapping fails.
pub(crate) enum SumsBuffer {
    Mapped(memmap2::MmapMut),
    Heap(Vec<[f32; 3]>),
}

impl SumsBuffer {
    /// Room for `n` sums, all zero.
    fn fresh(n: usize) -> Self {
        let bytes = n * size_of::<[f32; 3]>();
        match memmap2::MmapMut::map_anon(bytes.max(1)) {
            Ok(map) => {
                // A hint: where it is refused (`never`, other systems), 4 KiB pages it is.
                #[cfg(target_os = "linux")]
                let _ = map.advise(memmap2::Advice::HugePage);
                Self::Mapped(map)
            }
            Err(_) => Self::Heap(vec![[0.0; 3]; n]),
        }
    }

    /// How many sums it holds.
    fn len(&self) -> usize {
        match self {
            Self::Mapped(map) => map.len() / size_of::<[f32; 3]>(),
            Self::Heap(v) => v.len(),
        }
    }

    /// The first `n` sums as `Vec3`s (`n` at most [`SumsBuffer::len`]).
    pub(crate) fn vec3s_mut(&mut self, n: usize) -> &mut [Vec3] {
        match self {
            Self::Mapped(map) => bytemuck::cast_slice_mut(&mut map[..n * size_of::<[f32; 3]>()]),
            Self::Heap(v) => bytemuck::cast_slice_mut(&mut v[..n]),
        }
    }
}

/// Which of a ray's accelerator queries [`Tracer::visits_of`] replays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisitQuery {
    /// The ray's closest hit.
    Closest,
    /// The shadow ray towards light `light` (its index in the scene) from the ray's hit.
    Shadow { light: usize },
}

#[derive(Clone, Copy)]
enum Found {
    Nothing,
    /// A visible light and the distance to its surface.
    Light(usize, f32),
    Prim(PrimHit),
}

impl Found {
    /// The closest hit of a scene without visible lights: the primitive hit, or nothing.
    #[inline(always)]
    fn of(hit: Option<PrimHit>) -> Found {
        hit.map_or(Found::Nothing, Found::Prim)
    }
}

/// A primary ray's closest hit, its surface and its shadow rays' answers, found by packet
/// queries ([`Tracer::trace_packet`]).
#[derive(Clone, Copy)]
struct Given {
    found: Found,
    /// The surface and error bound of `found`'s hit, as [`Tracer::surface`] gives them, when
    /// `has_surface` (written in place: see [`Tracer::surface_into`]).
    surface: (SurfaceHit, Vec3),
    has_surface: bool,
    /// Bit `i`: the shadow ray towards light `i` is blocked (lights from 64 on are asked one
    /// ray at a time).
    blocked: u64,
    /// What [`Tracer::light_ray`] gave for each of the first [`GIVEN_LIGHTS`] lights, so
    /// shading does not set the shadow rays up a second time (the terms, where it formed them,
    /// are formed again: the same numbers); set when `surface` is. `Option`s, so that a fresh
    /// `Given` writes a tag per light instead of copying a whole placeholder.
    lights: [Option<LightRay>; GIVEN_LIGHTS],
}

/// The working state of [`Tracer::trace_packet`] for packets of `K` rays, kept by its caller
/// from one packet to the next so that its large records are written in place rather than
/// built on the stack and copied; its contents between calls mean nothing.
pub struct PacketScratch<const K: usize> {
    hits: [Option<PrimHit>; K],
    given: [Given; K],
    bases: [ShadowBase; K],
    shadow: [Ray; K],
    lengths: [f32; K],
}

impl<const K: usize> Default for PacketScratch<K> {
    fn default() -> Self {
        PacketScratch {
            hits: [None; K],
            given: [Given {
                found: Found::Nothing,
                surface: (PLACEHOLDER_SURFACE, Vec3::ZERO),
                has_surface: false,
                blocked: 0,
                lights: [None; GIVEN_LIGHTS],
            }; K],
            bases: [ShadowBase::default(); K],
            shadow: [Ray::new(Vec3::ZERO, Vec3::Z); K],
            lengths: [0.0; K],
        }
    }
}

/// Lights whose shadow-ray setup a packet keeps for shading (the rest are set up again).
const GIVEN_LIGHTS: usize = 4;

/// What a surface slot holds before [`Tracer::surface_into`] first fills it.
const PLACEHOLDER_SURFACE: SurfaceHit = SurfaceHit {
    t: 0.0,
    point: Vec3::ZERO,
    normal: Vec3::Z,
    geometric_normal: Vec3::Z,
    object: ObjectId(0),
    material: MaterialId(0),
    front_face: true,
    barycentric: None,
    vertex_normals: None,
    uv: None,
    texel_kd: None,
    texel_ka: None,
};

impl Given {
    #[inline(always)]
    fn blocked(&self, light: usize) -> Option<bool> {
        (light < 64).then(|| self.blocked >> light & 1 != 0)
    }
}

/// Most rays in one packet of [`Tracer::trace_packet`] (a mask of `u32` bits).
pub const MAX_PACKET: usize = 32;

/// Records that a branch ended, and why, in the tree and in the pixel's facts.
#[inline(always)]
fn ended<R: Recorder>(s: &mut Sample<'_, R>, reason: EndReason) {
    s.rec.end(reason);
    s.info.ends |= 1 << reason as u8;
}

/// One ray of the tree: its kind, its depth (the primary ray has depth 0) and the weight of
/// its contribution to the pixel (the product of kr / kt from the root).
#[derive(Clone, Copy, Debug)]
struct Branch {
    kind: RayKind,
    depth: u32,
    weight: Vec3,
    /// Its direction was bent back across the geometric plane (STABILITY N2).
    corrected: bool,
}

/// What every ray of one sample adds to: the ray counts, the pixel's facts and the recorder.
struct Sample<'a, R> {
    counts: &'a mut RayCounts,
    info: &'a mut SampleInfo,
    rec: &'a mut R,
}

impl Tracer {
    pub fn new(scene: Arc<Scene>, settings: TraceSettings) -> Self {
        let start = std::time::Instant::now();
        // From the scene's own triangles: a `prim_set` copy would stay alive through the build.
        let spheres: Vec<(Vec3, f32)> =
            scene.spheres.iter().map(|s| (s.center, s.radius)).collect();
        let triangles = &scene.triangles;
        let accel = Arc::new(Accel::build_from(
            settings.accel,
            &spheres,
            triangles.len(),
            &|i: usize| triangles[i].vertices,
        ));
        let build_secs = start.elapsed().as_secs_f64();
        let mut tracer = Self::with_accel(scene, settings, accel);
        tracer.build_secs = build_secs;
        tracer
    }

    /// A tracer over an accelerator already built for this scene's spheres and triangles
    /// (the caller guarantees the geometry and `settings.accel` are unchanged).
    pub fn with_accel(scene: Arc<Scene>, settings: TraceSettings, accel: Arc<Accel>) -> Self {
        let visible_lights = (0..scene.lights.len())
            .filter(|&i| scene.lights[i].radius > 0.0)
            .collect();
        Self {
            scene,
            accel,
            settings,
            visible_lights,
            build_secs: 0.0,
            sums: std::sync::Mutex::new(None),
        }
    }

    /// Room for `n` sums for a batch render ([`SumsBuffer::vec3s_mut`]): the buffer of the last
    /// render (still holding its values: the caller zeroes each tile's part where its worker
    /// starts it) when it is large enough, otherwise fresh zeroed pages, which the workers
    /// fault in tile by tile, in parallel, instead of one thread writing it all before the
    /// first tile. Give it back with [`Tracer::keep_sums`].
    pub(crate) fn take_sums(&self, n: usize) -> SumsBuffer {
        let kept = self
            .sums
            .lock()
            .ok()
            .and_then(|mut kept| kept.take())
            .filter(|kept| kept.len() >= n);
        kept.unwrap_or_else(|| SumsBuffer::fresh(n))
    }

    /// Keeps `sums` for the next batch render ([`Tracer::take_sums`]).
    pub(crate) fn keep_sums(&self, sums: SumsBuffer) {
        if let Ok(mut kept) = self.sums.lock() {
            *kept = Some(sums);
        }
    }

    fn methods(&self) -> &Methods {
        &self.settings.methods
    }

    /// The distance along the ray to the closest object or visible light, as a traced ray
    /// would meet it: the scene view's depth image.
    pub fn first_hit_t(&self, ray: &Ray) -> Option<f32> {
        match self.intersect(ray) {
            Found::Nothing => None,
            Found::Light(_, t) => Some(t),
            Found::Prim(hit) => Some(hit.t),
        }
    }

    /// Closest object or visible light along the ray, strictly after its origin (`t > 0`).
    fn intersect(&self, ray: &Ray) -> Found {
        let hit = self
            .accel
            .closest_hit(self.methods(), ray, 0.0, f32::INFINITY);
        self.with_lights(ray, hit)
    }

    /// The closest object hit `hit` of `ray` (from the accelerator), or a visible light
    /// before it. Inlined for the common scene without visible lights, where it only wraps
    /// the hit.
    #[inline(always)]
    fn with_lights(&self, ray: &Ray, hit: Option<PrimHit>) -> Found {
        if self.visible_lights.is_empty() {
            return Found::of(hit);
        }
        self.with_visible_lights(ray, hit)
    }

    /// [`Tracer::with_lights`] when the scene has visible lights.
    #[inline(never)]
    fn with_visible_lights(&self, ray: &Ray, hit: Option<PrimHit>) -> Found {
        let mut found = Found::Nothing;
        let mut t_max = f32::INFINITY;
        if let Some(hit) = hit {
            t_max = hit.t;
            found = Found::Prim(hit);
        }
        for &i in &self.visible_lights {
            let light = &self.scene.lights[i];
            let sphere = self.methods().sphere;
            if let Some(t) = intersect_sphere(sphere, light.position, light.radius, ray, 0.0, t_max)
            {
                t_max = t;
                found = Found::Light(i, t);
            }
        }
        found
    }

    /// Traces one ray of `kind` at `depth` (the primary ray has depth 0) whose contribution to
    /// the pixel is scaled by `weight`; returns its colour.
    #[allow(clippy::too_many_arguments)]
    pub fn trace<R: Recorder>(
        &self,
        ray: &Ray,
        kind: RayKind,
        depth: u32,
        weight: Vec3,
        counts: &mut RayCounts,
        info: &mut SampleInfo,
        rec: &mut R,
    ) -> Vec3 {
        let branch = Branch {
            kind,
            depth,
            weight,
            corrected: false,
        };
        self.trace_ray(ray, branch, &mut Sample { counts, info, rec })
    }

    /// [`Tracer::trace`] of one ray of a sample.
    fn trace_ray<R: Recorder>(&self, ray: &Ray, b: Branch, s: &mut Sample<'_, R>) -> Vec3 {
        self.trace_ray_given(ray, b, s, None)
    }

    /// [`Tracer::trace_ray`], with the ray's closest hit and its shadow rays' answers already
    /// found by a packet query when `given` is set (the caller checked that the ray is traced:
    /// [`Tracer::ends_untraced`] is `None`).
    #[inline(always)]
    fn trace_ray_given<R: Recorder>(
        &self,
        ray: &Ray,
        b: Branch,
        s: &mut Sample<'_, R>,
        given: Option<&Given>,
    ) -> Vec3 {
        s.rec.enter(b.kind, b.depth, ray, b.weight);
        if b.corrected {
            s.rec.direction_corrected();
        }
        let background = self.scene.render.background;
        let color = if let Some(reason) = self.ends_untraced(b.depth, b.weight, s.info) {
            ended(s, reason);
            background
        } else {
            s.counts.count(b.kind);
            s.info.rays += 1;
            s.info.depth_reached = s.info.depth_reached.max(b.depth);
            let found = match given {
                Some(g) => g.found,
                None => self.intersect(ray),
            };
            match found {
                Found::Nothing => {
                    ended(s, EndReason::NoHit);
                    background
                }
                Found::Light(i, t) => {
                    if b.depth == 0 {
                        s.info.hit_t = t;
                    }
                    ended(s, EndReason::HitLight);
                    s.rec.light(i, t);
                    self.scene.lights[i].color
                }
                Found::Prim(hit) => self.shade(ray, &hit, given, b, s),
            }
        };
        s.rec.leave(color);
        color
    }

    /// Primary rays of neighbouring pixels traced together: sample colour and facts of
    /// `rays[i]` into `out[i]` for each bit `i` of `active`, rays added to `counts`. The
    /// closest hits are one packet query, the shadow rays of the hits towards each light
    /// another; reflected and refracted rays are traced one by one. Every colour and fact is
    /// the one [`Tracer::trace`] of the ray alone gives, bit for bit: the same intersection
    /// answers (see [`Accel::closest_hits`]) go through the same shading code.
    #[inline(always)]
    pub fn trace_packet<const K: usize>(
        &self,
        rays: &[Ray; K],
        active: u32,
        counts: &mut RayCounts,
        out: &mut [(Vec3, SampleInfo); K],
        scratch: &mut PacketScratch<K>,
    ) {
        const { assert!(K <= MAX_PACKET) };
        let primary = Branch {
            kind: RayKind::Primary,
            depth: 0,
            weight: Vec3::ONE,
            corrected: false,
        };
        if self
            .ends_untraced(0, Vec3::ONE, &SampleInfo::default())
            .is_some()
        {
            for i in set_bits(active) {
                let mut info = SampleInfo::default();
                let s = &mut Sample {
                    counts: &mut *counts,
                    info: &mut info,
                    rec: &mut NoRecord,
                };
                let c = self.trace_ray(&rays[i], primary, s);
                out[i] = (c, info);
            }
            return;
        }
        let m = self.methods();
        let scene = &*self.scene;
        let PacketScratch {
            hits,
            given,
            bases,
            shadow,
            lengths,
        } = scratch;
        // Inactive lanes are left alone by the query: none of the last packet's hits stay.
        *hits = [None; K];
        self.accel.closest_hits(m, rays, active, hits);
        // The hit triangles' records load together, not one miss per lane in turn.
        let n_spheres = scene.spheres.len();
        for hit in hits.iter().flatten() {
            if let Some(tri) = (hit.prim as usize)
                .checked_sub(n_spheres)
                .and_then(|i| scene.triangles.get(i))
            {
                crate::accel::prefetch(tri);
            }
        }
        // Field by field into the caller's slots: a `Given` is large, and a fresh array of
        // them would be built on the stack and copied.
        let no_visible_lights = self.visible_lights.is_empty();
        // The lanes with a surface to shade (bit `i` for lane `i`).
        let mut surfaces = 0u32;
        for (i, g) in given.iter_mut().enumerate() {
            // Written in each branch: a `Found` formed in one temporary for both and copied
            // into the slot is loaded across the end of the store that formed it, and stalls.
            if no_visible_lights {
                g.found = Found::of(hits[i]);
            } else {
                g.found = self.with_visible_lights(&rays[i], hits[i]);
            }
            g.has_surface = match g.found {
                Found::Prim(hit) if active & (1 << i) != 0 => {
                    self.surface_into(&rays[i], &hit, &mut g.surface);
                    true
                }
                _ => false,
            };
            surfaces |= u32::from(g.has_surface) << i;
            g.blocked = 0;
            g.lights = [None; GIVEN_LIGHTS];
            bases[i] = ShadowBase::default();
        }
        for (li, light) in scene.lights.iter().enumerate().take(64) {
            let mut cast = 0u32;
            // Only the lanes with a surface: one step per set bit.
            for i in set_bits(surfaces) {
                let (g, base) = (&mut given[i], &mut bases[i]);
                let (surface, error) = &g.surface;
                let material = scene.material(surface.material);
                let v = -rays[i].dir;
                let mut terms = None;
                let Found::Prim(hit) = g.found else { continue };
                let lr = self.light_ray::<NoRecord>(
                    surface, hit.prim, *error, material, v, light, base, &mut terms,
                );
                if let Some((ray, length)) = lr.ray {
                    shadow[i] = ray;
                    lengths[i] = length;
                    cast |= 1 << i;
                }
                if let Some(slot) = g.lights.get_mut(li) {
                    *slot = Some(lr);
                }
            }
            if cast != 0 {
                // Only the blocked lanes change: one step per set bit.
                let blocked = self.accel.occluded_packet(m, shadow, lengths, cast);
                for i in set_bits(blocked) {
                    given[i].blocked |= 1 << li;
                }
            }
        }
        for i in set_bits(active) {
            // In place: the facts are written where the caller reads them.
            let (color, info) = &mut out[i];
            if let Some(c) = self.shade_given_local(&rays[i], &given[i], counts, info) {
                *color = c;
                continue;
            }
            *info = SampleInfo::default();
            let s = &mut Sample {
                counts: &mut *counts,
                info,
                rec: &mut NoRecord,
            };
            *color = self.trace_ray_given(&rays[i], primary, s, Some(&given[i]));
        }
    }

    /// [`Tracer::trace_ray_given`] of a packet's primary ray `ray` whose hit is on a surface
    /// without reflection or refraction (the camera- and shadow-ray frame's every hit), its
    /// shadow rays set up and answered in `g` for each of the scene's lights: the same colour
    /// and facts, bit for bit (the same local terms in the same order; no child, so no end
    /// reason), without the general path's bookkeeping for children, recorders and lights
    /// beyond [`GIVEN_LIGHTS`]. `None`, with nothing counted or written, where the general
    /// path is needed. The caller checked that primary rays are traced at all.
    #[inline(always)]
    fn shade_given_local(
        &self,
        ray: &Ray,
        g: &Given,
        counts: &mut RayCounts,
        info: &mut SampleInfo,
    ) -> Option<Vec3> {
        let scene = &*self.scene;
        if !g.has_surface || scene.lights.len() > GIVEN_LIGHTS {
            return None;
        }
        let surface = &g.surface.0;
        let material = scene.material(surface.material);
        if material.reflectivity != Vec3::ZERO || material.transparency != Vec3::ZERO {
            return None;
        }
        let lights = &g.lights[..scene.lights.len()];
        if lights.iter().any(Option::is_none) {
            return None;
        }
        let (n, v) = (surface.normal, -ray.dir);
        let kd = texelled(material.diffuse, surface.texel_kd);
        let ka = texelled(material.ambient, surface.texel_ka);
        let ambient = ka * scene.render.ambient_light;
        let shading = scene.render.shading;
        let (mut diffuse, mut specular) = (Vec3::ZERO, Vec3::ZERO);
        let mut shadows = 0;
        for (li, light) in scene.lights.iter().enumerate() {
            let Some(LightRay {
                l, ray: Some(_), ..
            }) = lights[li]
            else {
                continue;
            };
            shadows += 1;
            if g.blocked >> li & 1 == 0 {
                let terms = light_terms_with(shading, material, kd, light.color, n, l, v);
                diffuse += terms.diffuse;
                specular += terms.specular;
            }
        }
        counts.primary += 1;
        counts.shadow += u64::from(shadows);
        *info = SampleInfo {
            depth_reached: 0,
            rays: 1 + shadows,
            ends: 0,
            normal: n,
            hit_t: surface.t,
        };
        Some(ambient + diffuse + specular)
    }

    /// Why a ray ends before it is traced, if it does: past the maximum depth; below the weight
    /// cutoff (adaptive depth); or in a sample that has used its ray budget (glass between
    /// mirrors doubles its rays every few levels).
    #[inline(always)]
    fn ends_untraced(&self, depth: u32, weight: Vec3, info: &SampleInfo) -> Option<EndReason> {
        if depth > self.scene.render.max_depth {
            Some(EndReason::MaxDepth)
        } else if weight.max_element() < self.settings.cutoff {
            Some(EndReason::Cutoff)
        } else if info.rays >= MAX_RAYS_PER_SAMPLE {
            Some(EndReason::Budget)
        } else {
            None
        }
    }

    /// Hit point, its error bound, normals, object, material, barycentrics and texture.
    /// Inlined into its callers: returned by value, its result is otherwise copied.
    #[inline(always)]
    fn surface(&self, ray: &Ray, hit: &PrimHit) -> (SurfaceHit, Vec3) {
        let mut out = (PLACEHOLDER_SURFACE, Vec3::ZERO);
        self.surface_into(ray, hit, &mut out);
        out
    }

    /// [`Tracer::surface`] written field by field into `out` (a packet's slot): a surface
    /// formed in a temporary and copied into the slot reads its optional fields across the
    /// ends of the stores that wrote only their tags, and stalls.
    #[inline(always)]
    fn surface_into(&self, ray: &Ray, hit: &PrimHit, out: &mut (SurfaceHit, Vec3)) {
        let scene = &self.scene;
        let n_spheres = scene.spheres.len();
        let prim = hit.prim as usize;
        let mut vertex_normals = None;
        let mut uvs = None;
        let (point, error, normal, object, material, barycentric) = if prim < n_spheres {
            let s = &scene.spheres[prim];
            let (p, err) = sphere_hit_point(self.methods().sphere, s.center, s.radius, ray, hit.t);
            let n = div3(p - s.center, s.radius).normalize();
            (p, err, n, s.object, s.material, None)
        } else {
            let index = prim - n_spheres;
            let tri = &scene.triangles[index];
            let v = &tri.vertices;
            let (p, err) = triangle_hit_point(v, hit.b1, hit.b2);
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
            if let Some((attrs, local)) = scene.attributes_of(index) {
                vertex_normals = attrs.normals_of(local);
                uvs = attrs.uvs_of(local);
            }
            (p, err, n, tri.object, tri.material, Some(b))
        };
        let front_face = ray.dir.dot(normal) < 0.0;
        let side = if front_face { 1.0 } else { -1.0 };
        let geometric_normal = side * normal;
        let mut shading_normal = geometric_normal;
        let b = barycentric.unwrap_or([1.0, 0.0, 0.0]);
        if let Some(ns) = vertex_normals.as_mut() {
            *ns = ns.map(|n| side * n);
            if let Some(n) = interpolate_normal(ns, b) {
                shading_normal = n;
            }
        }
        let uv = uvs.map(|t| b[0] * t[0] + b[1] * t[1] + b[2] * t[2]);
        let (mut texel_kd, mut texel_ka) = (None, None);
        if let Some(uv) = uv {
            let m = scene.material(material);
            let texel = |map: Option<crate::scene::TextureId>| {
                map.and_then(|id| scene.texture(id)).map(|t| t.sample(uv))
            };
            texel_kd = texel(m.diffuse_map);
            texel_ka = texel(m.ambient_map);
        }
        // Field by field: a whole `SurfaceHit` assigned at once is formed on the stack and
        // copied (+0.2 % instructions on the 80k bench frame).
        let (surface, out_error) = out;
        surface.t = hit.t;
        surface.point = point;
        surface.normal = shading_normal;
        surface.geometric_normal = geometric_normal;
        surface.object = object;
        surface.material = material;
        surface.front_face = front_face;
        surface.barycentric = barycentric;
        surface.vertex_normals = vertex_normals;
        surface.uv = uv;
        surface.texel_kd = texel_kd;
        surface.texel_ka = texel_ka;
        *out_error = error;
    }

    /// Light `light` at a hit (`surface` of primitive `prim`, its point's error bound `error`,
    /// its material, `v` towards the viewer): the unit vector `L` to the light, the distance,
    /// the shadow ray with its length when one is cast, and whether the light is behind the
    /// geometric surface (STABILITY N3, robust; then no ray either). No ray where `N·L ≤ 0` or
    /// the light's unshadowed contribution is exactly zero (see [`casts_shadow_ray`]). `terms`
    /// gets the light's terms when the recorder is on or the decision needed them. The one
    /// place that decides, for the single and the packet trace alike.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn light_ray<R: Recorder>(
        &self,
        surface: &SurfaceHit,
        prim: u32,
        error: Vec3,
        material: &crate::scene::Material,
        v: Vec3,
        light: &crate::scene::Light,
        base: &mut ShadowBase,
        terms: &mut Option<LightTerms>,
    ) -> LightRay {
        let (p, n) = (surface.point, surface.normal);
        let shading = self.scene.render.shading;
        let to_light = light.position - p;
        let distance = to_light.length();
        let l = div3(to_light, distance);
        let kd = texelled(material.diffuse, surface.texel_kd);
        if R::ENABLED {
            *terms = Some(light_terms_with(
                shading,
                material,
                kd,
                light.color,
                n,
                l,
                v,
            ));
        }
        let mut out = LightRay {
            l,
            distance,
            ray: None,
            behind_surface: false,
        };
        if !(n.dot(l) > 0.0 && casts_shadow_ray(shading, material, kd, light.color, n, l, v, terms))
        {
            return out;
        }
        match self.shadow_start(surface, prim, error, l, base) {
            Some((q, q_error, side)) => {
                // Only objects count as blockers, never lights.
                let offset = self.methods().offset;
                let ng = surface.geometric_normal;
                // The origin depends on the side only through `side·ng < 0` (see
                // `offset_ray_origin`): the `+ng` one is shared by the hit's lights.
                let origin = match base.origin_up {
                    _ if side.dot(ng) < 0.0 => offset_ray_origin(offset, q, q_error, ng, side),
                    Some(origin) => origin,
                    None => {
                        let origin = offset_ray_origin(offset, q, q_error, ng, ng);
                        base.origin_up = Some(origin);
                        origin
                    }
                };
                out.ray = Some(shadow_ray(origin, light.position));
            }
            None => out.behind_surface = true,
        }
        out
    }

    /// Where the shadow ray towards a light in direction `l` starts, the error bound of that
    /// point and the side it is offset to; `None` when the light adds nothing without one
    /// (STABILITY N3, robust: the light is behind the geometric surface and the smooth surface
    /// does not reach above it). Flat surfaces, and the naive method, start from the hit point
    /// offset to the light's side.
    #[inline(always)]
    fn shadow_start(
        &self,
        surface: &SurfaceHit,
        prim: u32,
        error: Vec3,
        l: Vec3,
        base: &mut ShadowBase,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let (p, ng) = (surface.point, surface.geometric_normal);
        let robust = self.methods().shading_normals == ShadingNormals::Robust;
        // By reference: the three vertex normals are not copied for flat surfaces.
        let (true, Some(ns), Some(b)) = (robust, &surface.vertex_normals, surface.barycentric)
        else {
            return Some((p, error, l));
        };
        // N1 (Hanika 2021): from the smooth surface, when it lies outside the flat one, offset
        // to the visible side: a light behind the surface is then reached only past its edge
        // (N3), never through it. The same point for every light of the hit.
        let in_front = ng.dot(l) > 0.0;
        let terminator = match base.terminator {
            Some(known) => known,
            None => {
                let index = prim as usize - self.scene.spheres.len();
                let v = &self.scene.triangles[index].vertices;
                let found = terminator_origin(v, ns, b, p, error, ng);
                base.terminator = Some(found);
                found
            }
        };
        match terminator {
            Some((q, q_error, clear)) if in_front || clear => Some((q, q_error, ng)),
            _ => in_front.then_some((p, error, l)),
        }
    }

    /// The colour of a ray `b` that hit `hit`: the local model with a shadow ray per light,
    /// then the reflected and refracted children.
    ///
    /// `given` holds what a packet query found for a primary ray (its surface, its shadow rays
    /// and their answers); without it everything is found here, one ray at a time.
    #[inline(always)]
    fn shade<R: Recorder>(
        &self,
        ray: &Ray,
        hit: &PrimHit,
        given: Option<&Given>,
        b: Branch,
        s: &mut Sample<'_, R>,
    ) -> Vec3 {
        let scene = &*self.scene;
        let offset = self.methods().offset;
        // The surface, and the shadow rays' setups and answers, the packet found, if any (by
        // reference: they are large).
        let found_here;
        let (surface, error, known) = match given.filter(|g| g.has_surface) {
            Some(g) => (&g.surface.0, g.surface.1, Some(g)),
            None => {
                found_here = self.surface(ray, hit);
                (&found_here.0, found_here.1, None)
            }
        };
        let (p, n, ng) = (surface.point, surface.normal, surface.geometric_normal);
        let v = -ray.dir;
        s.rec.hit(surface, v);
        if b.depth == 0 {
            s.info.normal = n;
            s.info.hit_t = surface.t;
        }
        let material = scene.material(surface.material);
        // Texels multiply kd and ka where the material has textures (flat colours otherwise).
        let kd = texelled(material.diffuse, surface.texel_kd);
        let ka = texelled(material.ambient, surface.texel_ka);
        let terms_of = |color: Vec3, l: Vec3| {
            light_terms_with(scene.render.shading, material, kd, color, n, l, v)
        };

        let ambient = ka * scene.render.ambient_light;
        let mut base = ShadowBase::default();
        let mut diffuse = Vec3::ZERO;
        let mut specular = Vec3::ZERO;
        for (i, light) in scene.lights.iter().enumerate() {
            // The recorder shows every light's terms; tiles need them only for lights that
            // are not blocked, so they compute them after the shadow ray (N·L is the same
            // product `light_terms` forms, so the answer is unchanged).
            let mut terms = None;
            let LightRay {
                l,
                distance,
                ray: cast,
                behind_surface,
            } = match known.and_then(|g| g.lights.get(i).copied().flatten()) {
                Some(lr) => lr,
                None => self.light_ray::<R>(
                    surface, hit.prim, error, material, v, light, &mut base, &mut terms,
                ),
            };
            let mut blocked_by = None;
            let mut blocked_at = None;
            if let Some((shadow_ray, length)) = cast {
                s.counts.count(RayKind::Shadow);
                s.info.rays += 1;
                let blocked = if R::ENABLED {
                    let blocker = self
                        .accel
                        .closest_hit(self.methods(), &shadow_ray, 0.0, length);
                    blocked_by = blocker.map(|b| self.object_of(b.prim));
                    blocked_at = blocker.map(|b| b.t);
                    blocker.is_some()
                } else {
                    match known.and_then(|g| g.blocked(i)) {
                        Some(blocked) => blocked,
                        None => self
                            .accel
                            .occluded(self.methods(), &shadow_ray, 0.0, length),
                    }
                };
                if !blocked {
                    let terms = terms.unwrap_or_else(|| terms_of(light.color, l));
                    diffuse += terms.diffuse;
                    specular += terms.specular;
                }
            }
            if let Some(terms) = terms {
                s.rec.shadow(&ShadowTest {
                    light: i,
                    to_light: l,
                    distance,
                    blocked_by,
                    blocked_at,
                    traced: cast.is_some(),
                    behind_surface,
                    terms,
                });
            }
        }
        s.rec.local(ambient, diffuse, specular);
        let mut color = ambient + diffuse + specular;

        // Children: refraction first decides whether its weight moves to the reflected ray
        // (total internal reflection); the sum is then formed in the fixed order R, T.
        let kr = material.reflectivity;
        let kt = material.transparency;
        let mut reflected_weight = kr;
        let mut refracted = None;
        if kt != Vec3::ZERO {
            // Entering the solid goes from air (η = 1) to the material, leaving goes back.
            let eta = if surface.front_face {
                1.0 / material.ior
            } else {
                material.ior
            };
            match refract(ray.dir, n, eta) {
                Some(t) => refracted = Some(t),
                None => {
                    s.rec.total_internal_reflection();
                    reflected_weight += kt;
                }
            }
        }
        s.rec.child_weights(
            reflected_weight,
            if refracted.is_some() { kt } else { Vec3::ZERO },
        );
        // Each child leaves the surface on the side it goes to and carries its weight. About a
        // shading normal, a direction can cross the geometric plane into the surface it
        // leaves; the robust method mirrors it back (STABILITY N2).
        let keep = surface.vertex_normals.is_some()
            && self.methods().shading_normals == ShadingNormals::Robust;
        let child = |kind, dir: Vec3, k: Vec3, s: &mut Sample<'_, R>| {
            let (dir, corrected) = if keep {
                keep_side(dir, ng, kind == RayKind::Reflected)
            } else {
                (dir, false)
            };
            let ray = Ray::new(offset_ray_origin(offset, p, error, ng, dir), dir);
            let branch = Branch {
                kind,
                depth: b.depth + 1,
                weight: b.weight * k,
                corrected,
            };
            k * self.trace_ray(&ray, branch, s)
        };
        if reflected_weight != Vec3::ZERO {
            let r = reflect(ray.dir, n).normalize();
            color += child(RayKind::Reflected, r, reflected_weight, s);
        }
        if let Some(t) = refracted {
            color += child(RayKind::Refracted, t, kt, s);
        }
        color
    }

    /// Replays one ray's accelerator query with the boxes it entered and the primitives it
    /// tested, for a ray-tree [`Node`](crate::ray_tree::Node) (its offset `origin` and unit
    /// `direction`): [`VisitQuery::Closest`] is the node's own query, `(0, ∞)` as
    /// [`Tracer::trace`] casts it, so its hit is the node's unless a visible light ended the ray
    /// first (lights are not in the accelerator); [`VisitQuery::Shadow`] is the shadow ray the
    /// render casts from that hit towards a light (same offset origin and length), answered by
    /// the occlusion query the image uses. A shadow query whose ray hits no surface, or whose
    /// light is behind the surface (no shadow ray is cast), or out of range, visits nothing.
    pub fn visits_of(&self, origin: Vec3, direction: Vec3, query: VisitQuery) -> Visits {
        let ray = Ray::new(origin, direction);
        let m = self.methods();
        let closest = self.accel.closest_hit_visits(m, &ray, 0.0, f32::INFINITY);
        let VisitQuery::Shadow { light } = query else {
            return closest;
        };
        let (Some(hit), Some(light)) = (closest.hit, self.scene.lights.get(light)) else {
            return Visits::default();
        };
        let (surface, error) = self.surface(&ray, &hit);
        // As in `shade`: no shadow ray unless N·L > 0 and the light can add something, and
        // from where `shade` starts it.
        let material = self.scene.material(surface.material);
        let v = -ray.dir;
        match self
            .light_ray::<NoRecord>(
                &surface,
                hit.prim,
                error,
                material,
                v,
                light,
                &mut ShadowBase::default(),
                &mut None,
            )
            .ray
        {
            Some((shadow, length)) => self.accel.occluded_visits(m, &shadow, 0.0, length),
            _ => Visits::default(),
        }
    }

    /// The object a primitive id belongs to.
    pub fn object_of(&self, prim: u32) -> ObjectId {
        let prim = prim as usize;
        let n_spheres = self.scene.spheres.len();
        if prim < n_spheres {
            self.scene.spheres[prim].object
        } else {
            self.scene.triangles[prim - n_spheres].object
        }
    }
}

/// Whether a light in front of the surface (`N·L > 0`) needs a shadow ray (`kd` is the
/// material's diffuse times its texel, where textured): not when its
/// unshadowed contribution is exactly zero, so the ray could not change the pixel. The diffuse
/// term is `(C_l ⊙ kd)·N·L` and the specular `(C_l ⊙ ks)·spec`: when `C_l ⊙ kd` has a non-zero
/// channel the ray is cast; otherwise the terms are formed (into `terms`, when not already
/// there) and the ray is cast only when the specular is not exactly zero (a NaN is cast, so
/// it reaches the pixel as before). Both the render and the tree (and [`Tracer::visits_of`])
/// decide here, so a light the tree marks "not traced: contributes nothing" is one the image
/// did not trace.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn casts_shadow_ray(
    shading: crate::scene::Shading,
    material: &crate::scene::Material,
    kd: Vec3,
    color: Vec3,
    n: Vec3,
    l: Vec3,
    v: Vec3,
    terms: &mut Option<LightTerms>,
) -> bool {
    if color * kd != Vec3::ZERO {
        return true;
    }
    // Not `get_or_insert_with`: left to the heuristics, that generic call was sometimes
    // not inlined, and the terms' arithmetic with it.
    let t = match *terms {
        Some(t) => t,
        None => {
            let t = light_terms_with(shading, material, kd, color, n, l, v);
            *terms = Some(t);
            t
        }
    };
    t.specular != Vec3::ZERO || t.diffuse != Vec3::ZERO
}

/// The indices of the set bits of `mask`, lowest first: one step per set bit (a packet's
/// lanes; a filter over all of them pays for the empty ones too).
#[inline(always)]
fn set_bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// A material's colour times its texel, where the surface is textured.
#[inline(always)]
fn texelled(colour: Vec3, texel: Option<Vec3>) -> Vec3 {
    match texel {
        Some(t) => colour * t,
        None => colour,
    }
}

/// One light seen from a hit: the unit vector to it, its distance, the shadow ray and its
/// length when one is cast, and whether it is behind the geometric surface (STABILITY N3).
#[derive(Clone, Copy)]
struct LightRay {
    l: Vec3,
    distance: f32,
    ray: Option<(Ray, f32)>,
    behind_surface: bool,
}

/// What every shadow ray of one hit shares, found for the first light that needs it: where
/// the rays start (STABILITY N1) and that start offset to the side the geometric normal points
/// to. A hit's lights differ only in their directions, so the second light reuses both.
#[derive(Clone, Copy, Default)]
struct ShadowBase {
    /// [`terminator_origin`]'s answer, once asked (robust shading normals on a smooth triangle).
    terminator: Option<Option<(Vec3, Vec3, bool)>>,
    /// The offset origin towards the `+ng` side, once formed.
    origin_up: Option<Vec3>,
}

/// The shadow ray from `origin` (the hit point offset to the side of the surface the ray
/// leaves to: the light's side, or the visible side for robust shading normals, so the ray
/// never starts behind the surface, STABILITY N3) to the light's centre at `light`, and its
/// length.
#[inline(always)]
fn shadow_ray(origin: Vec3, light: Vec3) -> (Ray, f32) {
    let segment = light - origin;
    let length = segment.length();
    (Ray::new(origin, div3(segment, length)), length)
}

/// `v / s`, the three quotients in one SSE division: each lane rounds exactly as the scalar
/// `/` of glam's `Vec3`, so the result is the same bit for bit, for a third of the cost
/// (divisions are a fifth of the shading time).
#[inline(always)]
fn div3(v: Vec3, s: f32) -> Vec3 {
    (Vec3A::from(v) / s).into()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fresh sums are zero, hold what is written, and come back from `keep_sums` while they
    /// are large enough; a larger render gets a fresh, zeroed buffer; an empty one works.
    #[test]
    fn sums_buffers_are_zeroed_kept_and_replaced() {
        let scene =
            Arc::new(crate::scene::builtin::load_builtin("default").expect("built-in scene"));
        let tracer = Tracer::new(scene, TraceSettings::default());
        let mut empty = tracer.take_sums(0);
        assert!(empty.vec3s_mut(0).is_empty());
        let mut sums = tracer.take_sums(1000);
        assert!(sums.len() >= 1000);
        assert!(sums.vec3s_mut(1000).iter().all(|v| *v == Vec3::ZERO));
        sums.vec3s_mut(1000)[999] = Vec3::new(1.0, 2.0, 3.0);
        tracer.keep_sums(sums);
        // Smaller: the kept buffer, values and all (the render zeroes each tile's part).
        let mut again = tracer.take_sums(1000);
        assert_eq!(again.vec3s_mut(1000)[999], Vec3::new(1.0, 2.0, 3.0));
        tracer.keep_sums(again);
        let bigger = 1_000_000;
        let mut fresh = tracer.take_sums(bigger);
        assert!(fresh.vec3s_mut(bigger).iter().all(|v| *v == Vec3::ZERO));
        fresh.vec3s_mut(bigger)[bigger - 1] = Vec3::ONE;
    }
}
