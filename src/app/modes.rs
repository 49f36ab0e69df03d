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
pub fn ramp(t: f32) -> Vec3 {
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
        ImageMode::Cost => ramp((aux.rays.max(1) as f32).log2() / COST_OCTAVES as f32),
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

/// What a mode's colours mean, for the scale drawn beside the image: the one description
/// the viewer's legend reads, made from the same functions that paint the pixels.
#[derive(Clone, Debug, PartialEq)]
pub enum ColourScale {
    /// A value mapped along [`ramp`]: `ticks` are (position in 0..=1, value as text), lowest
    /// first; `units` says what the value counts.
    Ramp {
        title: &'static str,
        units: &'static str,
        ticks: Vec<(f32, String)>,
    },
    /// Named classes with their colours (linear).
    Classes {
        title: &'static str,
        note: &'static str,
        entries: Vec<(String, Vec3)>,
    },
}

/// The most rays the cost ramp tells apart: 2^COST_OCTAVES (more are drawn at its top).
pub const COST_OCTAVES: u32 = 8;

/// The colour scale of `mode` at `max_depth`; `None` for the render itself.
pub fn colour_scale(mode: ImageMode, max_depth: u32) -> Option<ColourScale> {
    match mode {
        ImageMode::Render => None,
        ImageMode::Depth => {
            let max = max_depth.max(1);
            let step = max.div_ceil(8);
            let mut ticks: Vec<(f32, String)> = (0..=max)
                .step_by(step as usize)
                .map(|d| (d as f32 / max as f32, d.to_string()))
                .collect();
            if ticks.last().map(|t| t.0) != Some(1.0) {
                ticks.push((1.0, max.to_string()));
            }
            Some(ColourScale::Ramp {
                title: "Depth reached",
                units: "generations of rays below the primary (0: no reflected or refracted ray)",
                ticks,
            })
        }
        ImageMode::Cost => Some(ColourScale::Ramp {
            title: "Cost",
            units: "rays traced for the pixel's first sample, shadow rays included (log scale)",
            ticks: (0..=COST_OCTAVES)
                .map(|k| {
                    let label = if k == COST_OCTAVES {
                        format!("{}+", 1u32 << k)
                    } else {
                        (1u32 << k).to_string()
                    };
                    (k as f32 / COST_OCTAVES as f32, label)
                })
                .collect(),
        }),
        ImageMode::Termination => Some(ColourScale::Classes {
            title: "Termination",
            note: "how the pixel's rays ended; the first reason listed wins",
            entries: TERMINATION_LEGEND
                .iter()
                .map(|(label, (r, g, b))| (label.to_string(), srgb(*r, *g, *b)))
                .collect(),
        }),
        ImageMode::Normals => {
            let at = |n: Vec3| {
                let aux = SampleInfo {
                    normal: n,
                    ..SampleInfo::default()
                };
                mode_color(ImageMode::Normals, &aux, max_depth)
            };
            Some(ColourScale::Classes {
                title: "Normals",
                note: "colour = 0.5·N + 0.5 of the surface normal N at the primary hit (world axes)",
                entries: vec![
                    ("+x".to_string(), at(Vec3::X)),
                    ("−x".to_string(), at(Vec3::NEG_X)),
                    ("+y".to_string(), at(Vec3::Y)),
                    ("−y".to_string(), at(Vec3::NEG_Y)),
                    ("+z".to_string(), at(Vec3::Z)),
                    ("−z".to_string(), at(Vec3::NEG_Z)),
                    ("no hit".to_string(), Vec3::ZERO),
                ],
            })
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

    /// The scale's ticks sit where the pixels of those values are painted.
    #[test]
    fn scales_match_the_painted_colours() {
        for mode in ImageMode::ALL {
            assert_eq!(colour_scale(mode, 5).is_none(), mode == ImageMode::Render);
        }
        let Some(ColourScale::Ramp { ticks, .. }) = colour_scale(ImageMode::Depth, 5) else {
            panic!("depth has a ramp");
        };
        assert_eq!(ticks.len(), 6);
        for (t, label) in ticks {
            let aux = SampleInfo {
                depth_reached: label.parse().expect("a number"),
                ..SampleInfo::default()
            };
            assert_eq!(ramp(t), mode_color(ImageMode::Depth, &aux, 5), "{label}");
        }
        let Some(ColourScale::Ramp { ticks, .. }) = colour_scale(ImageMode::Cost, 5) else {
            panic!("cost has a ramp");
        };
        let (t, label) = &ticks[4];
        assert_eq!(label, "16");
        let aux = SampleInfo {
            rays: 16,
            ..SampleInfo::default()
        };
        assert_eq!(ramp(*t), mode_color(ImageMode::Cost, &aux, 5));
        // Deep trees: at most about nine ticks, the maximum always labelled.
        let Some(ColourScale::Ramp { ticks, .. }) = colour_scale(ImageMode::Depth, 50) else {
            panic!("depth has a ramp");
        };
        assert!(ticks.len() <= 10 && ticks.last().map(|t| t.1.as_str()) == Some("50"));
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), srgb(68, 1, 84));
        assert_eq!(ramp(1.0), srgb(253, 231, 37));
    }
}
