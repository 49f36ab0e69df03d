//! The recursive trace of the lecture's pseudocode (docs/design.md, "The model"), generic over a
//! [`Recorder`]: tiles use [`NoRecord`], whose calls compile away; a clicked pixel uses the tree
//! recorder of [`crate::ray_tree`], so the tree and the image can never disagree.
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
//!
//! This file holds that recursion ([`Tracer::trace`]: shading, the shadow test of each light,
//! the reflected and refracted children, the termination conditions). Beside it: `surface`
//! (what a hit is: point, normals, texels), `shadow` (where a light's shadow ray starts and
//! whether it is cast at all) and `packet` (primary rays of neighbouring pixels traced
//! together, [`Tracer::trace_packet`], answering the same questions in packets and then
//! shading each ray with this file's code).

mod packet;
mod shadow;
mod surface;

use std::any::Any;
use std::sync::{Arc, Mutex};

use glam::{Vec2, Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::accel::{Accel, AccelKind, PrimHit, PrimSet, Visits};
use crate::geometry::{
    Methods, Ray, ShadingNormals, intersect_sphere, keep_side, offset_ray_origin,
};
use crate::scene::{MaterialId, ObjectId, Scene};
use crate::shade::{LightTerms, light_terms_with, reflect, refract};
use packet::Given;
pub use packet::{MAX_PACKET, PacketScratch};
use shadow::{LightRay, ShadowBase};

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

/// Why a branch of the tree ended without being shaded (the `end` of a node, docs/design.md, "The
/// ray tree as data").
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
    /// The blocker's primitive (spheres first, then triangles), to name its mesh part.
    pub blocker: Option<u32>,
    /// Distance along the shadow ray (from its offset origin) to the blocker.
    pub blocked_at: Option<f32>,
    /// Whether the shadow ray was cast: not when the light is behind the surface (`N·L ≤ 0`)
    /// nor when its unshadowed contribution is exactly zero (see `casts_shadow_ray`).
    pub traced: bool,
    /// The shading normal faces the light but the light is behind the geometric surface and the
    /// smooth surface does not reach above it (docs/stability.md, row N3): the light adds nothing,
    /// and no shadow ray is cast.
    pub behind_surface: bool,
    pub terms: LightTerms,
}

/// Receives every step of one trace. All methods default to doing nothing.
pub trait Recorder {
    /// `false` lets the trace skip work done only for the recorder (finding the blocker's name).
    const ENABLED: bool;
    fn enter(&mut self, _kind: RayKind, _depth: u32, _ray: &Ray, _weight: Vec3) {}
    /// The ray just entered had its direction mirrored back across the geometric plane of the
    /// surface it leaves (docs/stability.md, row N2).
    fn direction_corrected(&mut self) {}
    fn end(&mut self, _reason: EndReason) {}
    /// The ray ended on visible light `light` at distance `t`.
    fn light(&mut self, _light: usize, _t: f32) {}
    /// The primitive (spheres first, then triangles) the surface of the next `hit` belongs to,
    /// for names finer than its object's (an OBJ's `o` and `g`).
    fn hit_primitive(&mut self, _primitive: u32) {}
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
    /// The batch render's per-pixel sums (`render::sums::SumsBuffer`), kept from one render to
    /// the next so that a repeated render (`--frames`, a turntable) writes into memory the
    /// process has already touched instead of faulting in fresh pages. The tracer holds them
    /// because it is what lives from one render to the next (`render::render` takes only the
    /// tracer) and is dropped with the scene; the type belongs to the render, a layer above
    /// this one, so the slot holds it without naming it.
    pub(crate) kept_sums: Mutex<Option<Box<dyn Any + Send>>>,
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
    /// Its direction was bent back across the geometric plane (docs/stability.md, row N2).
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
            kept_sums: Mutex::new(None),
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

    /// [`Tracer::first_hit_t`] with the unit shading normal there, turned towards the ray
    /// (zero on a visible light), as a pixel's facts have them: the scene view's outlines.
    /// [`Tracer::first_hit_normal`] is the geometric normal of objects alone.
    pub fn first_hit_facts(&self, ray: &Ray) -> Option<(f32, Vec3)> {
        match self.intersect(ray) {
            Found::Nothing => None,
            Found::Light(_, t) => Some((t, Vec3::ZERO)),
            Found::Prim(hit) => Some((hit.t, self.surface(ray, &hit).0.normal)),
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
        s.rec.hit_primitive(hit.prim);
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
            let mut blocker_prim = None;
            let mut blocked_at = None;
            if let Some((shadow_ray, length)) = cast {
                s.counts.count(RayKind::Shadow);
                s.info.rays += 1;
                let blocked = if R::ENABLED {
                    let blocker = self
                        .accel
                        .closest_hit(self.methods(), &shadow_ray, 0.0, length);
                    blocked_by = blocker.map(|b| self.object_of(b.prim));
                    blocker_prim = blocker.map(|b| b.prim);
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
                    blocker: blocker_prim,
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
        // leaves; the robust method mirrors it back (docs/stability.md, row N2).
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

/// A material's colour times its texel, where the surface is textured.
#[inline(always)]
fn texelled(colour: Vec3, texel: Option<Vec3>) -> Vec3 {
    match texel {
        Some(t) => colour * t,
        None => colour,
    }
}

/// `v / s`, the three quotients in one SSE division: each lane rounds exactly as the scalar
/// `/` of glam's `Vec3`, so the result is the same bit for bit, for a third of the cost
/// (divisions are a fifth of the shading time).
#[inline(always)]
fn div3(v: Vec3, s: f32) -> Vec3 {
    (Vec3A::from(v) / s).into()
}
