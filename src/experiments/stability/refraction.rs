//! R1: refraction (docs/stability.md, row R1). NaN directions on total internal reflection,
//! Snell's law residual, the round trip through a surface and back.

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::{Row, StabilityOptions, Verdict, fmt_g, pct};
use crate::rng::Pcg;
use crate::shade::refract;

/// The refraction as commonly written without the total-internal-reflection check: glam's
/// `Vec3::refract` (which returns the zero vector on TIR), normalised as a direction must be.
pub fn refract_unguarded(u: Vec3, n: Vec3, eta: f32) -> Vec3 {
    u.refract(n, eta).normalize()
}

/// R1 figures for one index of refraction and direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RefractCell {
    pub ior: f32,
    pub entering: bool,
    pub rays: usize,
    /// Rays past the critical angle (exact arithmetic on the `f32` inputs).
    pub tir: usize,
    /// NaN directions from [`refract_unguarded`].
    pub naive_nan: usize,
    /// NaN directions from `shade::refract`.
    pub guarded_nan: usize,
    /// Rays where `shade::refract` reports TIR and exact arithmetic does not, or the reverse
    /// (ignoring rays within `1e-6` of the critical angle).
    pub tir_mismatch: usize,
    /// Largest `| |T| − 1 |`.
    pub max_len_err: f64,
    /// Largest `|(ηt/ηi)·sin θt − sin θi|`, in `f64` from the `f32` vectors.
    pub max_snell_residual: f64,
    /// Largest `|refract(−T, −n, 1/η) + u|`: refraction reversed must give the incoming ray.
    /// Near the critical angle `cos θt = sqrt(k)` turns an `ε` error of `k` into `sqrt(ε)`.
    pub max_roundtrip_err: f64,
    /// The same for rays with `cos θi ≥ 0.1` and `cos θt ≥ 0.1` (neither grazing, away from
    /// the critical angle).
    pub max_roundtrip_err_regular: f64,
    /// Reversed refractions that reported TIR.
    pub roundtrip_tir: usize,
}

/// R1: `n` rays with `cos θi` evenly from 1 to 0 at random orientations, into (`entering`) or
/// out of a medium of index `ior`.
pub fn refract_cell(ior: f32, entering: bool, n: usize, rng: &mut Pcg) -> RefractCell {
    let eta = if entering { 1.0 / ior } else { ior };
    let mut cell = RefractCell {
        ior,
        entering,
        rays: n,
        ..RefractCell::default()
    };
    for i in 0..n {
        let cos_i = 1.0 - i as f32 / (n.max(2) - 1) as f32;
        let nrm = rng.unit();
        let tangent = rng.perpendicular(nrm);
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        let u = (sin_i * tangent - cos_i * nrm).normalize();
        // Exact TIR test on the f32 inputs.
        let cos_exact = -DVec3::from(u).dot(DVec3::from(nrm));
        let k = 1.0 - f64::from(eta).powi(2) * (1.0 - cos_exact * cos_exact);
        let tir = k < 0.0;
        cell.tir += usize::from(tir);
        cell.naive_nan += usize::from(refract_unguarded(u, nrm, eta).is_nan());
        let guarded = refract(u, nrm, eta);
        if guarded.is_none() != tir && k.abs() > 1e-6 {
            cell.tir_mismatch += 1;
        }
        let Some(t) = guarded else { continue };
        cell.guarded_nan += usize::from(t.is_nan());
        let (td, ud, nd) = (DVec3::from(t), DVec3::from(u), DVec3::from(nrm));
        cell.max_len_err = cell.max_len_err.max((td.length() - 1.0).abs());
        let sin_t = td.cross(nd).length() / td.length();
        let sin_i = ud.cross(nd).length() / ud.length();
        // The target's form (docs/stability.md, row R1): η·sin θt − sin θi with η = ηt/ηi = 1/eta.
        let residual = (sin_t / f64::from(eta) - sin_i).abs();
        cell.max_snell_residual = cell.max_snell_residual.max(residual);
        match refract(-t, -nrm, 1.0 / eta) {
            Some(back) => {
                let err = (DVec3::from(back) + ud).length();
                cell.max_roundtrip_err = cell.max_roundtrip_err.max(err);
                if td.dot(nd).abs() >= 0.1 && cos_exact >= 0.1 {
                    cell.max_roundtrip_err_regular = cell.max_roundtrip_err_regular.max(err);
                }
            }
            None => cell.roundtrip_tir += 1,
        }
    }
    cell
}

/// `refract` with `η = 1`: the largest `|T − u|` over `n` random rays (the target: `T = u`).
pub fn refract_identity_err(n: usize, rng: &mut Pcg) -> f64 {
    let mut worst = 0f64;
    for _ in 0..n {
        let nrm = rng.unit();
        let mut u = rng.unit();
        if u.dot(nrm) > 0.0 {
            u = -u;
        }
        if let Some(t) = refract(u, nrm, 1.0) {
            worst = worst.max((DVec3::from(t) - DVec3::from(u)).length());
        } else {
            worst = f64::INFINITY;
        }
    }
    worst
}

pub(super) fn row_r1(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let mut cells = Vec::new();
    for ior in [1.0f32, 1.33, 1.5, 2.42] {
        for entering in [true, false] {
            cells.push(refract_cell(ior, entering, o.rays, rng));
        }
    }
    let identity = refract_identity_err(o.rays, rng);
    let max = |f: fn(&RefractCell) -> f64| cells.iter().map(f).fold(0.0, f64::max);
    let guarded_nan: usize = cells.iter().map(|c| c.guarded_nan).sum();
    let mismatch: usize = cells.iter().map(|c| c.tir_mismatch).sum();
    let snell = max(|c| c.max_snell_residual);
    let roundtrip = max(|c| c.max_roundtrip_err);
    let roundtrip_regular = max(|c| c.max_roundtrip_err_regular);
    let len = max(|c| c.max_len_err);
    let exit15 = cells
        .iter()
        .find(|c| c.ior == 1.5 && !c.entering)
        .copied()
        .unwrap_or_default();
    let naive_nan: usize = cells.iter().map(|c| c.naive_nan).sum();
    let tir: usize = cells.iter().map(|c| c.tir).sum();
    Row {
        id: "R1",
        failure: "NaN directions on total internal reflection, Snell's law residual",
        naive_method: "glam Vec3::refract, normalised (no TIR check)",
        robust_method: "shade::refract: TIR test, then Snell",
        sweep: format!(
            "cos θi from 1 to 0, entering and exiting, η ∈ {{1, 1.33, 1.5, 2.42}}, {} rays each",
            o.rays
        ),
        naive: format!(
            "{naive_nan} NaN directions ({tir} TIR rays); exiting η = 1.5: {:.0}% NaN",
            pct(exit15.naive_nan, exit15.rays)
        ),
        robust: format!(
            "{guarded_nan} NaN; TIR verdict wrong on {mismatch}; Snell residual ≤ {}; \
             | |T|−1 | ≤ {}; refract∘refract error ≤ {} for cos θi, cos θt ≥ 0.1, ≤ {} at \
             grazing angles; η = 1: |T − u| ≤ {} (cos²θt as (1 − η²) + η²cos²θi: no \
             cancellation at grazing angles)",
            fmt_g(snell),
            fmt_g(len),
            fmt_g(roundtrip_regular),
            fmt_g(roundtrip),
            fmt_g(identity)
        ),
        target: "0 NaN; TIR iff η²(1−cos²) > 1; Snell residual ≤ 1e-6; η = 1 gives T = u",
        verdict: if guarded_nan == 0 && mismatch == 0 && snell <= 1e-6 && naive_nan > 0 {
            // T = u exactly for η = 1 is not reached (see the measured |T − u|).
            if identity == 0.0 && roundtrip_regular <= 1e-6 {
                Verdict::Yes
            } else {
                Verdict::Partly
            }
        } else {
            Verdict::No
        },
        chart: None,
    }
}
