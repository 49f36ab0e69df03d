//! Image modes beside the render: what each pixel's sample-0 tree did, as colours. Colours are
//! given in sRGB and returned linear, since the display shader encodes sRGB itself.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::trace::{EndReason, SampleInfo};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ImageMode {
    /// The render itself.
    #[default]
    Render,
    /// Deepest ray of the pixel's tree, 0 to max depth.
    Depth,
    /// How the branches of the tree ended.
    Termination,
    /// Rays traced for the pixel's sample 0 (shadow rays included), on a log scale.
    Cost,
    /// Normal at the primary hit, `0.5·N + 0.5`.
    Normals,
}

impl ImageMode {
    pub const ALL: [ImageMode; 5] = [
        ImageMode::Render,
        ImageMode::Depth,
        ImageMode::Termination,
        ImageMode::Cost,
        ImageMode::Normals,
    ];

    pub fn label(self) -> &'static str {
        match self {
            ImageMode::Render => "Render",
            ImageMode::Depth => "Depth reached",
            ImageMode::Termination => "Termination",
            ImageMode::Cost => "Cost (rays/pixel)",
            ImageMode::Normals => "Normals",
        }
    }
}

fn srgb(r: u8, g: u8, b: u8) -> Vec3 {
    let f = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    Vec3::new(f(r), f(g), f(b))
}

/// A perceptual ramp (viridis stops) at `t` in [0, 1].
fn ramp(t: f32) -> Vec3 {
    const STOPS: [(u8, u8, u8); 5] = [
        (68, 1, 84),
        (59, 82, 139),
        (33, 145, 140),
        (94, 201, 98),
        (253, 231, 37),
    ];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    srgb(a.0, a.1, a.2).lerp(srgb(b.0, b.1, b.2), f)
}

/// The legend of the termination mode: the most telling reason wins.
pub const TERMINATION_LEGEND: [(&str, (u8, u8, u8)); 6] = [
    ("ray budget used up", (157, 78, 221)),
    ("max depth reached", (230, 57, 70)),
    ("weight cutoff", (244, 162, 97)),
    ("hit a light", (255, 221, 87)),
    ("escaped (no hit)", (69, 123, 157)),
    ("primary miss / local only", (60, 60, 60)),
];

fn has(ends: u8, reason: EndReason) -> bool {
    ends & (1 << reason as u8) != 0
}

/// The colour of a pixel in `mode` (`Render` is not handled here).
pub fn mode_color(mode: ImageMode, aux: &SampleInfo, max_depth: u32) -> Vec3 {
    match mode {
        ImageMode::Render => Vec3::ZERO,
        ImageMode::Depth => ramp(aux.depth_reached as f32 / max_depth.max(1) as f32),
        ImageMode::Termination => {
            let pick = if has(aux.ends, EndReason::Budget) {
                0
            } else if has(aux.ends, EndReason::MaxDepth) {
                1
            } else if has(aux.ends, EndReason::Cutoff) {
                2
            } else if has(aux.ends, EndReason::HitLight) {
                3
            } else if has(aux.ends, EndReason::NoHit) && aux.normal != Vec3::ZERO {
                4
            } else {
                5
            };
            let (r, g, b) = TERMINATION_LEGEND[pick].1;
            srgb(r, g, b)
        }
        ImageMode::Cost => ramp((aux.rays.max(1) as f32).log2() / 8.0),
        ImageMode::Normals => {
            if aux.normal == Vec3::ZERO {
                Vec3::ZERO
            } else {
                let c = aux.normal * 0.5 + 0.5;
                srgb(
                    (c.x * 255.0) as u8,
                    (c.y * 255.0) as u8,
                    (c.z * 255.0) as u8,
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn termination_prefers_max_depth() {
        let aux = SampleInfo {
            ends: (1 << EndReason::NoHit as u8) | (1 << EndReason::MaxDepth as u8),
            normal: Vec3::Y,
            ..SampleInfo::default()
        };
        let (r, g, b) = TERMINATION_LEGEND[1].1;
        assert_eq!(mode_color(ImageMode::Termination, &aux, 5), srgb(r, g, b));
    }

    /// A sample cut short by its ray budget has its own colour, apart from the weight cutoff's,
    /// and wins over every other reason.
    #[test]
    fn termination_tells_the_budget_from_the_cutoff() {
        let color = |ends: &[EndReason]| {
            let aux = SampleInfo {
                ends: ends.iter().fold(0, |bits, &e| bits | 1 << e as u8),
                normal: Vec3::Y,
                ..SampleInfo::default()
            };
            mode_color(ImageMode::Termination, &aux, 5)
        };
        let legend = |i: usize| {
            let (r, g, b) = TERMINATION_LEGEND[i].1;
            srgb(r, g, b)
        };
        assert_eq!(color(&[EndReason::Cutoff]), legend(2));
        assert_eq!(
            color(&[EndReason::Budget, EndReason::MaxDepth, EndReason::Cutoff]),
            legend(0)
        );
        let colours: std::collections::HashSet<_> =
            TERMINATION_LEGEND.iter().map(|(_, c)| *c).collect();
        assert_eq!(
            colours.len(),
            TERMINATION_LEGEND.len(),
            "two reasons share a colour"
        );
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), srgb(68, 1, 84));
        assert_eq!(ramp(1.0), srgb(253, 231, 37));
    }
}
