//! Primary rays of neighbouring pixels traced together ([`Tracer::trace_packet`]): one packet
//! query for their closest hits, one per light for their shadow rays, then each ray shaded by
//! the single-ray code of the parent module with those answers given, so every colour and fact
//! is the one [`Tracer::trace`] of the ray alone gives, bit for bit.

use glam::Vec3;

use super::shadow::{LightRay, ShadowBase};
use super::surface::PLACEHOLDER_SURFACE;
use super::{
    Branch, Found, NoRecord, RayCounts, RayKind, Sample, SampleInfo, SurfaceHit, Tracer, texelled,
};
use crate::accel::PrimHit;
use crate::geometry::Ray;
use crate::shade::light_terms_with;

/// A primary ray's closest hit, its surface and its shadow rays' answers, found by packet
/// queries ([`Tracer::trace_packet`]).
#[derive(Clone, Copy)]
pub(super) struct Given {
    pub(super) found: Found,
    /// The surface and error bound of `found`'s hit, as [`Tracer::surface`] gives them, when
    /// `has_surface` (written in place: see [`Tracer::surface_into`]).
    pub(super) surface: (SurfaceHit, Vec3),
    pub(super) has_surface: bool,
    /// Bit `i`: the shadow ray towards light `i` is blocked (lights from 64 on are asked one
    /// ray at a time).
    pub(super) blocked: u64,
    /// What [`Tracer::light_ray`] gave for each of the first [`GIVEN_LIGHTS`] lights, so
    /// shading does not set the shadow rays up a second time (the terms, where it formed them,
    /// are formed again: the same numbers); set when `surface` is. `Option`s, so that a fresh
    /// `Given` writes a tag per light instead of copying a whole placeholder.
    pub(super) lights: [Option<LightRay>; GIVEN_LIGHTS],
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

thread_local! {
    /// Each thread's [`PacketScratch`], kept from one tile to the next.
    static SCRATCH: std::cell::RefCell<Option<Box<PacketScratch<MAX_PACKET>>>> =
        const { std::cell::RefCell::new(None) };
}

impl PacketScratch<MAX_PACKET> {
    /// This thread's scratch, kept by [`PacketScratch::keep`] after its last tile (a fresh
    /// one the first time).
    pub fn take() -> Box<Self> {
        SCRATCH
            .try_with(|cell| cell.try_borrow_mut().ok().and_then(|mut slot| slot.take()))
            .ok()
            .flatten()
            .unwrap_or_default()
    }

    /// Keeps `scratch` for this thread's next [`PacketScratch::take`] (dropped if the thread
    /// is ending).
    pub fn keep(scratch: Box<Self>) {
        let _ = SCRATCH.try_with(|cell| {
            if let Ok(mut slot) = cell.try_borrow_mut() {
                *slot = Some(scratch);
            }
        });
    }
}

/// Lights whose shadow-ray setup a packet keeps for shading (the rest are set up again).
const GIVEN_LIGHTS: usize = 4;

impl Given {
    #[inline(always)]
    pub(super) fn blocked(&self, light: usize) -> Option<bool> {
        (light < 64).then(|| self.blocked >> light & 1 != 0)
    }
}

/// Most rays in one packet of [`Tracer::trace_packet`] (a mask of `u32` bits).
pub const MAX_PACKET: usize = 32;

impl Tracer {
    /// Primary rays of neighbouring pixels traced together: sample colour and facts of
    /// `rays[i]` into `out[i]` for each bit `i` of `active`, rays added to `counts`. The
    /// closest hits are one packet query, the shadow rays of the hits towards each light
    /// another; reflected and refracted rays are traced one by one. Every colour and fact is
    /// the one [`Tracer::trace`] of the ray alone gives, bit for bit: the same intersection
    /// answers (see [`crate::accel::Accel::closest_hits`]) go through the same shading code.
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
