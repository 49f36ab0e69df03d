//! The ray tracing tree of one pixel as data (docs/design.md, "The ray tree as data"): the recorder
//! that builds it from the same [`Tracer::trace`] the image uses, and its JSON form.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::geometry::Ray;
use crate::scene::{CameraFrame, Scene, primary_ray};
use crate::trace::{
    EndReason, RayCounts, RayKind, Recorder, SampleInfo, ShadowTest, SurfaceHit, TraceSettings,
    Tracer,
};

/// Nodes recorded at most; deeper or wider trees are cut and marked truncated. Glass at depth
/// 64 has up to 2⁶⁵ branches, so the cap is what keeps a click responsive.
pub const MAX_NODES: usize = 4096;

/// Where a ray met a surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HitRecord {
    pub t: f32,
    pub point: Vec3,
    /// Unit shading normal (turned like the geometric one, towards the incoming ray's side):
    /// what the local model and R/T use.
    pub normal: Vec3,
    /// The object's name; for a face of a named OBJ object or group (`o`, `g`), that name
    /// after a colon: "kitchen: Cabinet_3".
    pub object: String,
    pub material: String,
    pub front_face: bool,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub barycentric: Option<[f32; 3]>,
    /// The triangle's own normal, where shading normals apply (the mesh has vertex normals):
    /// front/back, entering/leaving and the ray-origin offset follow it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub geometric_normal: Option<Vec3>,
    /// Texture coordinates, where a texture applies.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub uv: Option<[f32; 2]>,
    /// What multiplies the material's diffuse at the hit (linear RGB): the `map_Kd` texel at
    /// `uv`, times the vertex colour interpolated there when the mesh has colours.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub texel: Option<Vec3>,
}

/// A visible light met by a ray.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightHit {
    pub name: String,
    pub t: f32,
}

/// The local illumination terms at a hit, summed over lights.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalRecord {
    pub ambient: Vec3,
    pub diffuse: Vec3,
    pub specular: Vec3,
    pub total: Vec3,
}

/// One light's shadow ray.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShadowRecord {
    pub light: String,
    /// `L`, unit vector from the hit point to the light's centre.
    pub to_light: Vec3,
    pub distance: f32,
    /// The first object on the segment to the light, or `None` when lit (or facing away),
    /// named as [`HitRecord::object`].
    pub blocked_by: Option<String>,
    /// Distance from the hit point to the blocker along `to_light`.
    #[serde(default)]
    pub blocked_at: Option<f32>,
    /// `N·L ≤ 0`: the light is behind the surface, adds nothing and needs no shadow ray.
    pub facing_away: bool,
    /// In front of the surface but its unshadowed terms are exactly zero (kd and ks zero in
    /// the light's channels, or no specular where kd is zero): no shadow ray traced, as in the
    /// render ("not traced: contributes nothing").
    #[serde(default)]
    pub contributes_nothing: bool,
    /// The shading normal faces the light but the geometric surface does not, and the smooth
    /// surface does not reach above it (docs/stability.md, row N3, robust): the light adds nothing.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub behind_surface: bool,
    pub n_dot_l: f32,
    pub n_dot_h: f32,
    pub r_dot_v: f32,
    /// Blinn's halfway vector `H = normalize(L + V)`.
    pub halfway: Vec3,
    /// Phong's mirrored light direction `R_l = 2(N·L)N − L`.
    pub mirror: Vec3,
    /// This light's diffuse and specular terms as added (zero when blocked).
    pub diffuse: Vec3,
    pub specular: Vec3,
}

/// One ray of the tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Node {
    pub kind: RayKind,
    pub depth: u32,
    pub origin: Vec3,
    pub direction: Vec3,
    /// Product of kr / kt along the path from the root.
    pub weight: Vec3,
    pub end: Option<EndReason>,
    /// The visible light that ended the ray (`end` = `hit_light`) and the distance to it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<LightHit>,
    pub hit: Option<HitRecord>,
    /// `V`, unit vector from the hit towards the ray's origin.
    pub view: Option<Vec3>,
    /// The direction (reflected or refracted about a shading normal) crossed the geometric
    /// plane of the surface it left and was mirrored back (docs/stability.md, row N2).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub direction_corrected: bool,
    pub local: Option<LocalRecord>,
    pub shadow_rays: Vec<ShadowRecord>,
    pub total_internal_reflection: bool,
    /// Weight given to the reflected child: `kr`, plus `kt` on total internal reflection.
    #[serde(default)]
    pub kr: Option<Vec3>,
    /// Weight given to the refracted child (`kt`), zero on total internal reflection.
    #[serde(default)]
    pub kt: Option<Vec3>,
    /// `local + kr·reflected.color + kt·refracted.color`.
    pub color: Vec3,
    pub children: Vec<Node>,
}

impl Node {
    /// A ray just started: where it goes and what it weighs, nothing met or computed yet.
    pub fn new(kind: RayKind, depth: u32, origin: Vec3, direction: Vec3, weight: Vec3) -> Self {
        Self {
            kind,
            depth,
            origin,
            direction,
            weight,
            end: None,
            light: None,
            hit: None,
            view: None,
            direction_corrected: false,
            local: None,
            shadow_rays: Vec::new(),
            total_internal_reflection: false,
            kr: None,
            kt: None,
            color: Vec3::ZERO,
            children: Vec::new(),
        }
    }
}

/// What produced a tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeSettings {
    pub max_depth: u32,
    pub shading: crate::scene::Shading,
    pub trace: TraceSettings,
}

/// The tree of one pixel's centre sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RayTree {
    pub pixel: [u32; 2],
    /// The pixel's sample-0 value: equal to the 1-sample render.
    pub color: Vec3,
    pub settings: TreeSettings,
    /// Nodes recorded.
    pub nodes: usize,
    /// More rays were traced than [`MAX_NODES`]; the rest are in `color` but not in the tree.
    pub truncated: bool,
    pub rays: RayCounts,
    pub root: Node,
}

/// Builds [`Node`]s from the trace's callbacks with a stack.
struct TreeRecorder<'a> {
    scene: &'a Scene,
    /// The primitive of the hit about to be recorded, which names its mesh part.
    primitive: Option<u32>,
    stack: Vec<Node>,
    /// Depth of unrecorded nesting below the cap.
    skipped: u32,
    nodes: usize,
    truncated: bool,
    root: Option<Node>,
}

impl TreeRecorder<'_> {
    fn top(&mut self) -> Option<&mut Node> {
        if self.skipped > 0 {
            None
        } else {
            self.stack.last_mut()
        }
    }
}

impl Recorder for TreeRecorder<'_> {
    const ENABLED: bool = true;

    fn enter(&mut self, kind: RayKind, depth: u32, ray: &Ray, weight: Vec3) {
        if self.skipped > 0 || self.nodes >= MAX_NODES {
            self.skipped += 1;
            self.truncated = true;
            return;
        }
        self.nodes += 1;
        self.stack
            .push(Node::new(kind, depth, ray.origin, ray.dir, weight));
    }

    fn direction_corrected(&mut self) {
        if let Some(node) = self.top() {
            node.direction_corrected = true;
        }
    }

    fn end(&mut self, reason: EndReason) {
        if let Some(node) = self.top() {
            node.end = Some(reason);
        }
    }

    fn light(&mut self, light: usize, t: f32) {
        let scene = self.scene;
        if let Some(node) = self.top() {
            node.light = Some(LightHit {
                name: scene.lights[light].name.clone(),
                t,
            });
        }
    }

    fn hit_primitive(&mut self, primitive: u32) {
        self.primitive = Some(primitive);
    }

    fn hit(&mut self, hit: &SurfaceHit, view: Vec3) {
        let scene = self.scene;
        let primitive = self.primitive.take();
        if let Some(node) = self.top() {
            node.hit = Some(HitRecord {
                t: hit.t,
                point: hit.point,
                normal: hit.normal,
                object: scene.hit_name(hit.object, primitive),
                material: scene.material(hit.material).name.clone(),
                front_face: hit.front_face,
                barycentric: hit.barycentric,
                geometric_normal: hit.vertex_normals.map(|_| hit.geometric_normal),
                uv: hit
                    .uv
                    .filter(|_| hit.texel_kd.is_some() || hit.texel_ka.is_some())
                    .map(|t| t.to_array()),
                texel: hit.texel_kd,
            });
            node.view = Some(view);
        }
    }

    fn shadow(&mut self, test: &ShadowTest) {
        let scene = self.scene;
        if let Some(node) = self.top() {
            let lit = test.blocked_by.is_none() && !test.behind_surface && test.terms.n_dot_l > 0.0;
            let (n, v) = match (&node.hit, node.view) {
                (Some(h), Some(v)) => (h.normal, v),
                _ => (Vec3::ZERO, Vec3::ZERO),
            };
            let l = test.to_light;
            node.shadow_rays.push(ShadowRecord {
                light: scene.lights[test.light].name.clone(),
                to_light: test.to_light,
                distance: test.distance,
                blocked_by: test.blocked_by.map(|o| scene.hit_name(o, test.blocker)),
                blocked_at: test.blocked_at,
                facing_away: test.terms.n_dot_l.is_nan() || test.terms.n_dot_l <= 0.0,
                contributes_nothing: !test.traced
                    && test.terms.n_dot_l > 0.0
                    && !test.behind_surface,
                behind_surface: test.behind_surface,
                n_dot_l: test.terms.n_dot_l,
                n_dot_h: test.terms.n_dot_h,
                r_dot_v: test.terms.r_dot_v,
                halfway: crate::shade::halfway(l, v),
                mirror: crate::shade::reflect(-l, n),
                diffuse: if lit { test.terms.diffuse } else { Vec3::ZERO },
                specular: if lit { test.terms.specular } else { Vec3::ZERO },
            });
        }
    }

    fn local(&mut self, ambient: Vec3, diffuse: Vec3, specular: Vec3) {
        if let Some(node) = self.top() {
            node.local = Some(LocalRecord {
                ambient,
                diffuse,
                specular,
                total: ambient + diffuse + specular,
            });
        }
    }

    fn total_internal_reflection(&mut self) {
        if let Some(node) = self.top() {
            node.total_internal_reflection = true;
        }
    }

    fn child_weights(&mut self, reflected: Vec3, refracted: Vec3) {
        if let Some(node) = self.top() {
            node.kr = Some(reflected);
            node.kt = Some(refracted);
        }
    }

    fn leave(&mut self, color: Vec3) {
        if self.skipped > 0 {
            self.skipped -= 1;
            return;
        }
        let Some(mut node) = self.stack.pop() else {
            return;
        };
        node.color = color;
        match self.stack.last_mut() {
            Some(parent) => parent.children.push(node),
            None => self.root = Some(node),
        }
    }
}

/// Traces the centre sample of pixel (`x`, `y`) with a tree recorder. `None` when the pixel is
/// outside the image.
pub fn pixel_tree(tracer: &Tracer, x: u32, y: u32) -> Option<RayTree> {
    let scene = &*tracer.scene;
    let (w, h) = (scene.render.width, scene.render.height);
    if x >= w || y >= h {
        return None;
    }
    let frame = CameraFrame::new(&scene.camera, w, h);
    let ray = primary_ray(&frame, x, y, 0);
    let mut rec = TreeRecorder {
        scene,
        primitive: None,
        stack: Vec::new(),
        skipped: 0,
        nodes: 0,
        truncated: false,
        root: None,
    };
    let mut rays = RayCounts::default();
    let mut info = SampleInfo::default();
    let color = tracer.trace(
        &ray,
        RayKind::Primary,
        0,
        Vec3::ONE,
        &mut rays,
        &mut info,
        &mut rec,
    );
    Some(RayTree {
        pixel: [x, y],
        color,
        settings: TreeSettings {
            max_depth: scene.render.max_depth,
            shading: scene.render.shading,
            trace: tracer.settings,
        },
        nodes: rec.nodes,
        truncated: rec.truncated,
        rays,
        root: rec.root?,
    })
}

fn fmt_v(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

/// The tree as indented, readable text (what `raytree tree` prints without `--json`).
pub fn tree_text(tree: &RayTree) -> String {
    let mut out = format!(
        "pixel ({}, {}) colour {}  [{}{}; max_depth {}, {:?}]\n",
        tree.pixel[0],
        tree.pixel[1],
        fmt_v(tree.color),
        crate::plural::count(tree.nodes, "node"),
        if tree.truncated { ", truncated" } else { "" },
        tree.settings.max_depth,
        tree.settings.shading,
    );
    write_node(&mut out, &tree.root, 0);
    out
}

fn write_node(out: &mut String, node: &Node, indent: usize) {
    use std::fmt::Write;
    let pad = "  ".repeat(indent);
    let kind = match node.kind {
        RayKind::Primary => "primary",
        RayKind::Reflected => "R (reflected)",
        RayKind::Refracted => "T (refracted)",
        RayKind::Shadow => "shadow",
    };
    let _ = write!(
        out,
        "{pad}{kind} depth {} weight {} dir {}",
        node.depth,
        fmt_v(node.weight),
        fmt_v(node.direction)
    );
    if let Some(end) = node.end {
        let light = node
            .light
            .as_ref()
            .map(|l| format!(" ({} at t = {:.5})", l.name, l.t))
            .unwrap_or_default();
        let _ = writeln!(out, " -> {end:?}{light} => colour {}", fmt_v(node.color));
        return;
    }
    out.push('\n');
    if let Some(hit) = &node.hit {
        let _ = writeln!(
            out,
            "{pad}  hit {} ({}) at t = {:.5}, P = {}, N = {}{}{}{}{}{}",
            hit.object,
            hit.material,
            hit.t,
            fmt_v(hit.point),
            fmt_v(hit.normal),
            hit.geometric_normal
                .map(|n| format!(" (geometric {})", fmt_v(n)))
                .unwrap_or_default(),
            if hit.front_face { "" } else { ", inside" },
            hit.barycentric
                .map(|b| format!(", barycentric ({:.4}, {:.4}, {:.4})", b[0], b[1], b[2]))
                .unwrap_or_default(),
            hit.uv
                .map(|t| format!(", uv ({:.4}, {:.4})", t[0], t[1]))
                .unwrap_or_default(),
            hit.texel
                .map(|t| format!(
                    ", {} {}",
                    if hit.uv.is_some() {
                        "texel (× kd)"
                    } else {
                        "vertex colour (× kd)"
                    },
                    fmt_v(t)
                ))
                .unwrap_or_default(),
        );
    }
    for s in &node.shadow_rays {
        let verdict = match (&s.blocked_by, s.facing_away) {
            (_, true) => "facing away".to_string(),
            _ if s.contributes_nothing => "not traced: contributes nothing".to_string(),
            (Some(b), _) => format!(
                "blocked by {b}{}",
                s.blocked_at
                    .map(|d| format!(" at {d:.4}"))
                    .unwrap_or_default()
            ),
            (None, false) => "lit".to_string(),
        };
        let _ = writeln!(
            out,
            "{pad}  shadow ray to {}: {verdict}; L = {}, N·L = {:.4}, N·H = {:.4}, R·V = {:.4}, diffuse {}, specular {}",
            s.light,
            fmt_v(s.to_light),
            s.n_dot_l,
            s.n_dot_h,
            s.r_dot_v,
            fmt_v(s.diffuse),
            fmt_v(s.specular)
        );
    }
    if let Some(l) = &node.local {
        let _ = writeln!(
            out,
            "{pad}  local = ambient {} + diffuse {} + specular {} = {}",
            fmt_v(l.ambient),
            fmt_v(l.diffuse),
            fmt_v(l.specular),
            fmt_v(l.total)
        );
    }
    if node.total_internal_reflection {
        let _ = writeln!(out, "{pad}  total internal reflection: kt goes to R");
    }
    if let (Some(kr), Some(kt)) = (node.kr, node.kt)
        && !node.children.is_empty()
    {
        let _ = writeln!(
            out,
            "{pad}  children weighted kr {} and kt {}",
            fmt_v(kr),
            fmt_v(kt)
        );
    }
    for child in &node.children {
        write_node(out, child, indent + 1);
    }
    let _ = writeln!(out, "{pad}  => colour {}", fmt_v(node.color));
}
