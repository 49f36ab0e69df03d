//! What the pictures' colours mean: the colour scale beside an image mode (from
//! [`modes::colour_scale`]), the legend of ray colours and diagram glyphs for the help (from
//! [`diagram::legend`]), and a compact key of ray colours drawn in the views with rays. No colour
//! is defined here: each comes from the code that paints it.

use eframe::egui::{self, Color32, Pos2, Rect, Stroke, Ui, Vec2};
use glam::Vec3;

use super::modes::{ColourScale, ramp};
use super::tree_view::paint_mark;
use crate::diagram;

/// Width of the strip the colour scale takes beside the image.
pub const SCALE_WIDTH: f32 = 132.0;

/// A linear colour for the screen (egui converts to sRGB).
fn screen(c: Vec3) -> Color32 {
    Color32::from(egui::Rgba::from_rgb(c.x, c.y, c.z))
}

/// Draws `scale` in `ui` (a strip [`SCALE_WIDTH`] wide beside the image), its bar about
/// `height` points tall.
pub fn colour_scale_ui(ui: &mut Ui, scale: &ColourScale, height: f32) {
    let small = egui::TextStyle::Small;
    match scale {
        ColourScale::Ramp {
            title,
            units,
            ticks,
        } => {
            ui.strong(*title);
            let h = height.clamp(80.0, 360.0);
            let (rect, response) =
                ui.allocate_exact_size(Vec2::new(SCALE_WIDTH - 8.0, h), egui::Sense::hover());
            let lo = ticks.first().map(|t| t.1.clone()).unwrap_or_default();
            let hi = ticks.last().map(|t| t.1.clone()).unwrap_or_default();
            response.widget_info(|| {
                egui::WidgetInfo::labeled(
                    egui::Role::Image,
                    true,
                    format!("colour scale: {title} from {lo} to {hi}"),
                )
            });
            let bar =
                Rect::from_min_size(rect.min + Vec2::new(2.0, 6.0), Vec2::new(18.0, h - 12.0));
            let painter = ui.painter_at(rect);
            // The ramp from the bottom (low) to the top (high), in thin bands.
            let bands = 64;
            for k in 0..bands {
                let t0 = k as f32 / bands as f32;
                let t1 = (k + 1) as f32 / bands as f32;
                let y0 = bar.max.y - t1 * bar.height();
                let y1 = bar.max.y - t0 * bar.height();
                painter.rect_filled(
                    Rect::from_x_y_ranges(bar.x_range(), y0..=y1 + 0.5),
                    0.0,
                    screen(ramp((t0 + t1) * 0.5)),
                );
            }
            painter.rect_stroke(
                bar,
                0.0,
                Stroke::new(1.0, Color32::from_gray(140)),
                egui::StrokeKind::Outside,
            );
            let text = ui.visuals().text_color();
            let font = egui::TextStyle::Small.resolve(ui.style());
            for (t, label) in ticks {
                let y = bar.max.y - t * bar.height();
                painter.line_segment(
                    [Pos2::new(bar.max.x, y), Pos2::new(bar.max.x + 5.0, y)],
                    Stroke::new(1.0, text),
                );
                painter.text(
                    Pos2::new(bar.max.x + 8.0, y),
                    egui::Align2::LEFT_CENTER,
                    label,
                    font.clone(),
                    text,
                );
            }
            ui.add(egui::Label::new(egui::RichText::new(*units).text_style(small)).wrap());
        }
        ColourScale::Classes {
            title,
            note,
            entries,
        } => {
            ui.strong(*title);
            for (label, colour) in entries {
                ui.horizontal(|ui| {
                    let (r, _) = ui.allocate_exact_size(Vec2::splat(12.0), egui::Sense::hover());
                    ui.painter().rect_filled(r, 2.0, screen(*colour));
                    ui.painter().rect_stroke(
                        r,
                        2.0,
                        Stroke::new(1.0, Color32::from_gray(120)),
                        egui::StrokeKind::Outside,
                    );
                    ui.add(
                        egui::Label::new(egui::RichText::new(label).text_style(small.clone()))
                            .wrap(),
                    );
                });
            }
            ui.add(egui::Label::new(egui::RichText::new(*note).text_style(small)).wrap());
        }
    }
}

/// Every ray colour and diagram glyph with its meaning, one row each (the F1 help).
pub fn ray_legend_ui(ui: &mut Ui) {
    egui::Grid::new("ray legend").striped(true).show(ui, |ui| {
        for e in diagram::legend() {
            let (r, _) = ui.allocate_exact_size(Vec2::new(34.0, 16.0), egui::Sense::hover());
            paint_mark(ui.painter(), &e, r.center());
            ui.label(e.text);
            ui.end_row();
        }
    });
}

/// The ray entries of the legend a view with rays needs at a glance: primary, reflected,
/// refracted, shadow ray lit and blocked.
fn key_entries() -> Vec<diagram::LegendEntry> {
    diagram::legend()
        .into_iter()
        .filter(|e| {
            matches!(
                e.mark,
                diagram::Mark::Ray(_)
                    | diagram::Mark::Glyph(diagram::Glyph::Lit)
                    | diagram::Mark::Glyph(diagram::Glyph::Blocked)
            )
        })
        .collect()
}

/// Short names for the key (the legend's own text is a sentence).
fn key_label(e: &diagram::LegendEntry) -> &'static str {
    match e.mark {
        diagram::Mark::Ray(crate::trace::RayKind::Primary) => "primary",
        diagram::Mark::Ray(crate::trace::RayKind::Reflected) => "reflected",
        diagram::Mark::Ray(crate::trace::RayKind::Refracted) => "refracted",
        diagram::Mark::Ray(crate::trace::RayKind::Shadow) => "shadow",
        diagram::Mark::Glyph(diagram::Glyph::Lit) => "shadow: lit",
        diagram::Mark::Glyph(diagram::Glyph::Blocked) => "shadow: blocked",
        _ => e.text,
    }
}

/// A compact key of the ray colours in the bottom-left corner of a view `rect` with rays.
pub fn ray_key(painter: &egui::Painter, rect: Rect) {
    let entries = key_entries();
    let row = 15.0;
    let size = Vec2::new(128.0, 8.0 + row * entries.len() as f32);
    if rect.width() < size.x * 2.0 || rect.height() < size.y * 2.0 {
        return; // too small a view: the key would hide it
    }
    let area = Rect::from_min_size(Pos2::new(rect.min.x + 6.0, rect.max.y - size.y - 6.0), size);
    painter.rect_filled(area, 4.0, Color32::from_rgba_unmultiplied(25, 25, 25, 200));
    let font = egui::FontId::proportional(11.0);
    for (i, e) in entries.iter().enumerate() {
        let y = area.min.y + 4.0 + row * (i as f32 + 0.5);
        paint_mark(painter, e, Pos2::new(area.min.x + 20.0, y));
        painter.text(
            Pos2::new(area.min.x + 40.0, y),
            egui::Align2::LEFT_CENTER,
            key_label(e),
            font.clone(),
            Color32::from_gray(225),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_has_the_three_rays_and_both_shadow_outcomes() {
        let labels: Vec<&str> = key_entries().iter().map(key_label).collect();
        for want in [
            "primary",
            "reflected",
            "refracted",
            "shadow: lit",
            "shadow: blocked",
        ] {
            assert!(labels.contains(&want), "{want} missing from {labels:?}");
        }
        // The colours are the scene view's own.
        let reflected = key_entries()
            .into_iter()
            .find(|e| e.mark == diagram::Mark::Ray(crate::trace::RayKind::Reflected))
            .map(|e| e.rgba);
        let [r, g, b] = crate::scene_view::kind_rgb(crate::trace::RayKind::Reflected);
        assert_eq!(reflected, Some([r, g, b, 255]));
    }
}
