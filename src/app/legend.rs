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

/// Height of the strip the colour scale takes below the image (when the pane is narrow).
pub const SCALE_HEIGHT: f32 = 78.0;

/// Where the scale goes round an image of `w` × `h` pixels fitted into `avail`: the rectangle
/// left for the image and the strip for the scale. Beside the image when that costs it
/// nothing or the pane is wide, below it when there is room under it or the pane is narrow.
pub fn place_scale(avail: Rect, w: f32, h: f32) -> (Rect, Rect, bool) {
    let fit = (avail.width() / w).min(avail.height() / h);
    let spare_x = avail.width() - w * fit;
    let spare_y = avail.height() - h * fit;
    let beside =
        spare_x >= SCALE_WIDTH || (spare_y < SCALE_HEIGHT && avail.width() > 3.0 * SCALE_WIDTH);
    if beside {
        let x = avail.max.x - SCALE_WIDTH;
        (
            Rect::from_min_max(avail.min, Pos2::new(x, avail.max.y)),
            Rect::from_min_max(Pos2::new(x, avail.min.y), avail.max),
            false,
        )
    } else {
        // The image and the scale under it, centred together.
        let room = (avail.height() - SCALE_HEIGHT).max(1.0);
        let image_h = h * (avail.width() / w).min(room / h);
        let top = avail.center().y - 0.5 * (image_h + SCALE_HEIGHT);
        let y = top + image_h;
        (
            Rect::from_min_max(Pos2::new(avail.min.x, top), Pos2::new(avail.max.x, y)),
            Rect::from_min_max(
                Pos2::new(avail.min.x, y),
                Pos2::new(avail.max.x, y + SCALE_HEIGHT),
            ),
            true,
        )
    }
}

/// A linear colour for the screen (egui converts to sRGB).
fn screen(c: Vec3) -> Color32 {
    Color32::from(egui::Rgba::from_rgb(c.x, c.y, c.z))
}

/// Draws `scale` in `ui`: in a strip [`SCALE_WIDTH`] wide beside the image, its bar about
/// `length` points tall, or (`horizontal`) in a strip [`SCALE_HEIGHT`] tall below it, its bar
/// `length` points wide.
pub fn colour_scale_ui(ui: &mut Ui, scale: &ColourScale, length: f32, horizontal: bool) {
    if horizontal {
        return colour_scale_row(ui, scale, length);
    }
    let height = length;
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

/// [`colour_scale_ui`] laid out in a row below the image.
fn colour_scale_row(ui: &mut Ui, scale: &ColourScale, width: f32) {
    let small = egui::TextStyle::Small;
    match scale {
        ColourScale::Ramp {
            title,
            units,
            ticks,
        } => {
            ui.horizontal(|ui| {
                ui.strong(*title);
                ui.add(egui::Label::new(egui::RichText::new(*units).text_style(small)).truncate());
            });
            let w = width.clamp(120.0, 520.0);
            let (rect, response) = ui.allocate_exact_size(Vec2::new(w, 30.0), egui::Sense::hover());
            let lo = ticks.first().map(|t| t.1.clone()).unwrap_or_default();
            let hi = ticks.last().map(|t| t.1.clone()).unwrap_or_default();
            response.widget_info(|| {
                egui::WidgetInfo::labeled(
                    egui::Role::Image,
                    true,
                    format!("colour scale: {title} from {lo} to {hi}"),
                )
            });
            // Inset so the end labels ("256+") are not cut at the strip's edges.
            let bar =
                Rect::from_min_size(rect.min + Vec2::new(16.0, 0.0), Vec2::new(w - 32.0, 12.0));
            let painter = ui.painter_at(rect);
            let bands = 64;
            for k in 0..bands {
                let t0 = k as f32 / bands as f32;
                let t1 = (k + 1) as f32 / bands as f32;
                let x0 = bar.min.x + t0 * bar.width();
                let x1 = bar.min.x + t1 * bar.width();
                painter.rect_filled(
                    Rect::from_x_y_ranges(x0..=x1 + 0.5, bar.y_range()),
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
                let x = bar.min.x + t * bar.width();
                painter.line_segment(
                    [Pos2::new(x, bar.max.y), Pos2::new(x, bar.max.y + 4.0)],
                    Stroke::new(1.0, text),
                );
                painter.text(
                    Pos2::new(x, bar.max.y + 5.0),
                    egui::Align2::CENTER_TOP,
                    label,
                    font.clone(),
                    text,
                );
            }
        }
        ColourScale::Classes {
            title,
            note,
            entries,
        } => {
            ui.horizontal(|ui| {
                ui.strong(*title);
                ui.add(
                    egui::Label::new(egui::RichText::new(*note).text_style(small.clone()))
                        .truncate(),
                );
            });
            ui.horizontal_wrapped(|ui| {
                for (label, colour) in entries {
                    let (r, _) = ui.allocate_exact_size(Vec2::splat(12.0), egui::Sense::hover());
                    ui.painter().rect_filled(r, 2.0, screen(*colour));
                    ui.label(egui::RichText::new(label).text_style(small.clone()));
                    ui.add_space(6.0);
                }
            });
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
    fn the_scale_goes_where_it_costs_the_image_least() {
        // A wide pane round a square image: beside it, the image keeps its size.
        let avail = Rect::from_min_size(Pos2::ZERO, Vec2::new(800.0, 400.0));
        let (image, strip, below) = place_scale(avail, 200.0, 200.0);
        assert!(!below && strip.width() == SCALE_WIDTH && image.width() >= 400.0);
        // A narrow, tall pane: below.
        let avail = Rect::from_min_size(Pos2::ZERO, Vec2::new(360.0, 460.0));
        let (image, strip, below) = place_scale(avail, 200.0, 200.0);
        assert!(below && strip.height() == SCALE_HEIGHT && image.width() == 360.0);
        // Right under the image, which keeps its full width.
        assert_eq!(strip.min.y, image.max.y);
        assert_eq!(image.height(), 360.0);
        // Never overlapping.
        assert!(!image.intersects(strip.shrink(0.5)));
    }

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
