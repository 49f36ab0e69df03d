//! `raytree merge`: puts the parts of a render made on several machines (`raytree render
//! --region` or `--tile`) back into one image. Every part's stamp must say the same scene,
//! settings, samples and program; the parts must cover the image exactly once. Anything else
//! is refused with one sentence naming the part, and nothing is written.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use raytree::export::{self, KEY_REGION, KEY_SCENE_HASH, Pixels, StampHeader};
use raytree::render::{Image, Rect};

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The parts: PNG or EXR images written by `raytree render --region/--tile`, all of one
    /// kind.
    #[arg(required = true, value_name = "PART")]
    parts: Vec<PathBuf>,
    /// The merged image: .png (from PNG or EXR parts) or .exr (from EXR parts).
    #[arg(short, long)]
    output: PathBuf,
}

/// The stamp entries that must agree between parts, and what each is called in a refusal.
const MUST_AGREE: &[(&str, &str)] = &[
    ("Software", "program version"),
    ("raytree.samples", "samples"),
    ("raytree.settings", "settings"),
    (export::KEY_FRAME, "turntable frame"),
    (KEY_SCENE_HASH, "scene"),
];

pub fn run_merge(args: &MergeArgs) -> Result<()> {
    let out_ext = extension(&args.output);
    if !matches!(out_ext.as_deref(), Some("png" | "exr")) {
        bail!(
            "cannot write {}: the file name must end in .png (8-bit sRGB) or .exr (linear float)",
            args.output.display()
        );
    }
    // Headers first: nothing is decoded until every part is known to fit.
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        parts.push(export::read_stamp_header(path)?);
    }
    let (width, height) = check_parts(&args.parts, &parts)?;
    let first = &parts[0];
    let linear = first.linear;
    if out_ext.as_deref() == Some("exr") && !linear {
        bail!(
            "cannot write {}: the parts are 8-bit PNGs, and an EXR needs the linear float pixels \
             of EXR parts (render the parts as .exr, or merge to .png)",
            args.output.display()
        );
    }
    // The merged image's stamp: the first part's, with the whole image as its region, so it
    // reads as the single-machine render's.
    let text: Vec<(String, String)> = first
        .text
        .iter()
        .map(|(k, v)| {
            if k == KEY_REGION {
                (k.clone(), format!("0,0,{width},{height}"))
            } else {
                (k.clone(), v.clone())
            }
        })
        .collect();
    // Then each part's pixels in turn, copied into place and dropped.
    let (iw, ih) = if linear { (width, height) } else { (0, 0) };
    let mut image = Image::new(iw, ih);
    let mut bytes = vec![
        0u8;
        if linear {
            0
        } else {
            width as usize * height as usize * 3
        }
    ];
    for (path, header) in args.parts.iter().zip(&parts) {
        let part = export::read_stamped(path)?;
        let r = region_of(header);
        if (part.width, part.height) != (r.width, r.height) {
            bail!("{} changed while it was being merged", path.display());
        }
        match &part.pixels {
            Pixels::Linear(px) => {
                let w = r.width as usize;
                for j in 0..r.height as usize {
                    let at = (r.y as usize + j) * width as usize + r.x as usize;
                    image.pixels[at..at + w].copy_from_slice(&px[j * w..(j + 1) * w]);
                }
            }
            Pixels::Srgb8(px) if !linear => {
                let row = r.width as usize * 3;
                for j in 0..r.height as usize {
                    let at = ((r.y as usize + j) * width as usize + r.x as usize) * 3;
                    bytes[at..at + row].copy_from_slice(&px[j * row..(j + 1) * row]);
                }
            }
            Pixels::Srgb8(_) => bail!("{} changed while it was being merged", path.display()),
        }
    }
    if linear {
        export::write_image(&args.output, &image, &text)?;
    } else {
        export::write_png_rgb8(&args.output, width, height, &bytes, &text)?;
    }
    out!(
        "wrote {} ({width}x{height}, from {} parts)",
        args.output.display(),
        parts.len()
    );
    Ok(())
}

fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

fn region_of(part: &StampHeader) -> Rect {
    part.get(KEY_REGION)
        .and_then(export::parse_region)
        .unwrap_or(Rect {
            x: 0,
            y: 0,
            width: 0,
            height: 0,
        })
}

/// The full image's size from a part's settings stamp.
fn full_size(part: &StampHeader) -> Option<(u32, u32)> {
    let settings: serde_json::Value = serde_json::from_str(part.get("raytree.settings")?).ok()?;
    let w = u32::try_from(settings.get("width")?.as_u64()?).ok()?;
    let h = u32::try_from(settings.get("height")?.as_u64()?).ok()?;
    Some((w, h))
}

/// Checks that the parts belong together and cover the image once; returns its size.
fn check_parts(paths: &[PathBuf], parts: &[StampHeader]) -> Result<(u32, u32)> {
    let name = |i: usize| paths[i].display().to_string();
    let mut size = None;
    for (i, part) in parts.iter().enumerate() {
        let Some((w, h)) = full_size(part) else {
            bail!(
                "{} has no raytree stamp of its image size (raytree.settings); only images \
                 written by `raytree render` can be merged",
                name(i)
            );
        };
        let Some(r) = part.get(KEY_REGION).and_then(export::parse_region) else {
            bail!(
                "{} has no raytree region stamp (raytree.region); render parts with `raytree \
                 render --region` or `--tile`",
                name(i)
            );
        };
        if part.get(KEY_SCENE_HASH).is_none() {
            bail!(
                "{} has no raytree scene stamp (raytree.scene_hash)",
                name(i)
            );
        }
        if (r.width, r.height) != (part.width, part.height)
            || u64::from(r.x) + u64::from(r.width) > u64::from(w)
            || u64::from(r.y) + u64::from(r.height) > u64::from(h)
            || r.width == 0
            || r.height == 0
        {
            bail!(
                "{} is {}x{} pixels but its stamp says region {} of a {w}x{h} image; the part is \
                 damaged or edited",
                name(i),
                part.width,
                part.height,
                export::format_region(r)
            );
        }
        if i > 0 {
            let first = &parts[0];
            let (fw, fh) = size.unwrap_or((w, h));
            if (w, h) != (fw, fh) {
                bail!(
                    "{} is part of a {w}x{h} image but {} of a {fw}x{fh} one: parts of different \
                     renders cannot be merged",
                    name(i),
                    name(0)
                );
            }
            if part.linear != first.linear {
                bail!(
                    "{} is not of the same kind (PNG or EXR) as {}: merge parts of one kind",
                    name(i),
                    name(0)
                );
            }
            for (key, what) in MUST_AGREE {
                if part.get(key) != first.get(key) {
                    bail!(
                        "{} was rendered with a different {what} than {} ({key} `{}` vs `{}`): \
                         parts of different renders cannot be merged",
                        name(i),
                        name(0),
                        part.get(key).unwrap_or("none"),
                        first.get(key).unwrap_or("none")
                    );
                }
            }
        }
        size = Some((w, h));
    }
    let (w, h) = size.unwrap_or((0, 0));
    // Rectangles, not pixels (a poster's pixel map would take gigabytes): no two may share a
    // pixel, and then they cover the image once exactly when their areas add up to it.
    let rects: Vec<Rect> = parts.iter().map(region_of).collect();
    for (i, a) in rects.iter().enumerate() {
        for (j, b) in rects.iter().enumerate().take(i) {
            let (x0, y0) = (a.x.max(b.x), a.y.max(b.y));
            let (x1, y1) = (
                (a.x + a.width).min(b.x + b.width),
                (a.y + a.height).min(b.y + b.height),
            );
            if x0 < x1 && y0 < y1 {
                if paths[i] == paths[j] || a == b {
                    bail!(
                        "{} is given twice (or is the same part as {})",
                        name(i),
                        name(j)
                    );
                }
                bail!(
                    "{} overlaps {} at pixel ({x0}, {y0}): each pixel must come from exactly \
                     one part",
                    name(i),
                    name(j)
                );
            }
        }
    }
    let covered: u64 = rects
        .iter()
        .map(|r| u64::from(r.width) * u64::from(r.height))
        .sum();
    let total = u64::from(w) * u64::from(h);
    if covered < total {
        // The first uncovered pixel, row by row: the parts' spans on that row leave a gap.
        let mut first = (0, 0);
        'rows: for y in 0..h {
            let mut spans: Vec<(u32, u32)> = rects
                .iter()
                .filter(|r| r.y <= y && y < r.y + r.height)
                .map(|r| (r.x, r.x + r.width))
                .collect();
            spans.sort_unstable();
            let mut x = 0;
            for (lo, hi) in spans {
                if lo > x {
                    break;
                }
                x = x.max(hi);
            }
            if x < w {
                first = (x, y);
                break 'rows;
            }
        }
        bail!(
            "the parts leave {} of the {w}x{h} image's pixels uncovered, the first at ({}, {}): \
             a part is missing",
            total - covered,
            first.0,
            first.1
        );
    }
    Ok((w, h))
}
