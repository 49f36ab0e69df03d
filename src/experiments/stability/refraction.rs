//! R1: refraction (docs/stability.md, row R1). NaN directions on total internal reflection,
//! Snell's law residual, the round trip through a surface and back.

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::{Row, StabilityOptions, Verdict, chart, fmt_g, pct};
use crate::experiments::chart::Series;
use crate::rng::Pcg;
use crate::shade::refract;

/// The refraction as commonly written without the total-internal-reflection check: glam's
/// `Vec3::refract` (which returns the zero vector on TIR), normalised as a direction must be.
pub fn refract_unguarded(u: Vec3, n: Vec3, eta: f32) -> Vec3 {
    u.refract(n, eta).normalize()
}

/// R1's target for the round trip: the largest error over a bin of angles at most this many
/// times what exact arithmetic on the same `f32` inputs reaches in that bin.
pub const ROUNDTRIP_TARGET_RATIO: f64 = 3.0;

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

/// [`refract`] in exact-as-`f64` arithmetic on the same inputs: the formula of
/// `shade::refract` with every operation in `f64` and no rounding to `f32` at the end. The
/// inputs are taken as they are (an `f32` unit vector is unit only to within about ε), so this
/// is the best any implementation that is handed these `f32` vectors can do.
pub fn refract_f64(u: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = (-u.dot(n)).clamp(0.0, 1.0);
    let k = (1.0 - eta * eta) + eta * eta * (cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((eta * u - (k.sqrt() - eta * cos_i) * n).normalize())
}

/// The lower ends of the bins of [`roundtrip_bins`]: `min(cos θi, cos θt)` from 1 down to 1e-4.
pub const ROUNDTRIP_BINS: [f64; 9] = [0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 0.0];

/// The round trip `refract(−T, −n, 1/η)` against `−u`, in one bin of `min(cos θi, cos θt)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RoundTripBin {
    /// The bin is `(lo, hi]` of `min(cos θi, cos θt)`.
    pub lo: f64,
    pub hi: f64,
    pub rays: usize,
    /// Largest `|refract(−T, −n, 1/η) + u|` with `shade::refract` (`f32`) both ways.
    pub max_err: f64,
    /// The same with [`refract_f64`] both ways on the same `f32` `u` and `n`, `T` correctly
    /// rounded to `f32` in between: what exact arithmetic reaches when it is handed these
    /// `f32` vectors and must hand on an `f32` direction.
    pub max_err_exact: f64,
    /// Reversed refractions that reported total internal reflection (`f32`, exact).
    pub tir_back: usize,
    pub tir_back_exact: usize,
}

/// R1's round trip at grazing angles: `n` rays per bin of `min(cos θi, cos θt)`
/// ([`ROUNDTRIP_BINS`]), drawn log-uniformly in the bin (entering: by `cos θi`; exiting: by
/// `cos θt`, so that the bins near the critical angle fill too), through a surface of index
/// `ior` and back.
pub fn roundtrip_bins(ior: f32, entering: bool, n: usize, rng: &mut Pcg) -> Vec<RoundTripBin> {
    let eta = if entering { 1.0 / ior } else { ior };
    let mut hi = 1.0f64;
    let mut out = Vec::new();
    for &lo in &ROUNDTRIP_BINS {
        let mut bin = RoundTripBin {
            lo,
            hi,
            ..RoundTripBin::default()
        };
        let floor = lo.max(1e-6);
        for _ in 0..n {
            let c = floor * (hi / floor).powf(rng.f32() as f64);
            // With η = ηi/ηt: sin θt = η·sin θi.
            let cos_i = if entering {
                c
            } else {
                let sin_t2 = 1.0 - c * c;
                (1.0 - sin_t2 / f64::from(eta * eta)).max(0.0).sqrt()
            };
            let nrm = rng.unit();
            let tangent = rng.perpendicular(nrm);
            let cos_i = cos_i as f32;
            let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
            let u = (sin_i * tangent - cos_i * nrm).normalize();
            let (ud, nd) = (DVec3::from(u), DVec3::from(nrm));
            let Some(t_exact) = refract_f64(ud, nd, f64::from(eta)) else {
                continue;
            };
            bin.rays += 1;
            // The best an implementation that returns `f32` directions can hand on: T
            // correctly rounded to `f32`.
            let t_rounded = DVec3::from(t_exact.as_vec3());
            match refract_f64(-t_rounded, -nd, 1.0 / f64::from(eta)) {
                Some(back) => bin.max_err_exact = bin.max_err_exact.max((back + ud).length()),
                None => bin.tir_back_exact += 1,
            }
            match refract(u, nrm, eta).and_then(|t| refract(-t, -nrm, 1.0 / eta)) {
                Some(back) => {
                    bin.max_err = bin.max_err.max((DVec3::from(back) + ud).length());
                }
                None => bin.tir_back += 1,
            }
        }
        out.push(bin);
        hi = lo;
    }
    out
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
    // The round trip by bins of min(cos θi, cos θt), against exact arithmetic on the inputs.
    let per_bin = (o.rays / 2).max(100);
    let trips: Vec<(f32, bool, Vec<RoundTripBin>)> = [1.33f32, 1.5, 2.42]
        .iter()
        .flat_map(|&ior| [true, false].map(|e| (ior, e)))
        .map(|(ior, e)| (ior, e, roundtrip_bins(ior, e, per_bin, rng)))
        .collect();
    // The worst ratio over the bins (a bin where exact arithmetic has no error counts as
    // reached when the f32 error is below 1e-7 too).
    let ratio = |b: &RoundTripBin| {
        if b.max_err_exact > 0.0 {
            b.max_err / b.max_err_exact
        } else if b.max_err <= 1e-7 {
            1.0
        } else {
            f64::INFINITY
        }
    };
    let worst_ratio = trips
        .iter()
        .flat_map(|(_, _, bins)| bins.iter().filter(|b| b.rays > 0).map(ratio))
        .fold(0.0, f64::max);
    let tir_back: usize = trips.iter().flat_map(|t| &t.2).map(|b| b.tir_back).sum();
    let tir_back_exact: usize = trips
        .iter()
        .flat_map(|t| &t.2)
        .map(|b| b.tir_back_exact)
        .sum();
    let bin_max = |f: fn(&RoundTripBin) -> f64, lo: f64| {
        trips
            .iter()
            .flat_map(|t| &t.2)
            .filter(|b| b.lo == lo)
            .map(f)
            .fold(0.0, f64::max)
    };
    let mut series = Vec::new();
    for &(ior, entering) in &[(1.5f32, true), (2.42, true)] {
        let Some((_, _, bins)) = trips.iter().find(|t| t.0 == ior && t.1 == entering) else {
            continue;
        };
        let mid = |b: &RoundTripBin| (b.lo.max(3e-5) * b.hi).sqrt();
        series.push(Series::new(
            format!("shade::refract, into η = {ior}"),
            bins.iter().map(|b| (mid(b), b.max_err)).collect(),
        ));
        series.push(Series::new(
            format!("exact on the f32 inputs, T rounded to f32, η = {ior}"),
            bins.iter().map(|b| (mid(b), b.max_err_exact)).collect(),
        ));
    }
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
             | |T|−1 | ≤ {}; η = 1: |T − u| = {}; refract∘refract error ≤ {} for cos θi, \
             cos θt ≥ 0.1, ≤ {} at grazing angles (uniform cos θi); by bins of min(cos θi, \
             cos θt): ≤ {} (exact arithmetic on the same f32 inputs, T rounded to f32: {}) for ≥ 0.1, ≤ {} \
             (exact: {}) at 1e-3…3e-3, ≤ {} (exact: {}) below 1e-4; worst ratio to exact \
             {:.2}; reversed into TIR {} times (exact: {})",
            fmt_g(snell),
            fmt_g(len),
            fmt_g(identity),
            fmt_g(roundtrip_regular),
            fmt_g(roundtrip),
            fmt_g(bin_max(|b| b.max_err, 0.3).max(bin_max(|b| b.max_err, 0.1))),
            fmt_g(bin_max(|b| b.max_err_exact, 0.3).max(bin_max(|b| b.max_err_exact, 0.1))),
            fmt_g(bin_max(|b| b.max_err, 1e-3)),
            fmt_g(bin_max(|b| b.max_err_exact, 1e-3)),
            fmt_g(bin_max(|b| b.max_err, 0.0)),
            fmt_g(bin_max(|b| b.max_err_exact, 0.0)),
            worst_ratio,
            tir_back,
            tir_back_exact
        ),
        target: "0 NaN; TIR iff η²(1−cos²) > 1; Snell residual ≤ 1e-6; η = 1 gives T = u; \
                 round trip within 3× of exact arithmetic on the same f32 inputs (T rounded to f32) at every angle",
        verdict: if guarded_nan == 0
            && mismatch == 0
            && snell <= 1e-6
            && naive_nan > 0
            && identity == 0.0
            && worst_ratio <= ROUNDTRIP_TARGET_RATIO
        {
            Verdict::Yes
        } else if guarded_nan == 0 && mismatch == 0 && snell <= 1e-6 && naive_nan > 0 {
            Verdict::Partly
        } else {
            Verdict::No
        },
        chart: Some(chart(
            "R1: refracted there and back, against the grazing angle",
            "min(cos θi, cos θt)",
            "|refract(−T, −n, 1/η) + u|",
            true,
            series,
        )),
    }
}
