//! The lecture's recursive procedure as numbered lines ([`LINES`]), and which of them one
//! call of `trace` executed for a node of a real tree, with the values of its variables
//! ([`node_lines`]); [`walk`] gives every line of the whole recursion in the order it ran, a
//! child's call nested in its parent's `trace(q, r, step+1)` line, for a pane that
//! highlights the line being executed while a tree is stepped through.
//!
//! The lines follow the lecture's form; where the program differs it says so on the line:
//! children are traced only with a weight (`kr`, `kt`) above zero, the sum weights them, and a
//! total internal reflection gives `kt` to the reflected ray.

use glam::Vec3;

use crate::ray_tree::{Node, RayTree};
use crate::shade::reflect;
use crate::trace::{EndReason, RayKind};

/// One line of the procedure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    /// Stable name, for the pane and for tests.
    pub id: &'static str,
    /// Indentation level.
    pub indent: u8,
    pub text: &'static str,
}

const fn line(id: &'static str, indent: u8, text: &'static str) -> Line {
    Line { id, indent, text }
}

/// The procedure, in order.
pub const LINES: &[Line] = &[
    line("signature", 0, "color trace(point p, vector d, int step) {"),
    line(
        "max_depth",
        1,
        "if (step > max) return background_color;        // termination: maximum depth",
    ),
    line("intersect", 1, "q = intersect(p, d, status);"),
    line(
        "light",
        1,
        "if (status == light_source) return light_color; // termination: a light source",
    ),
    line(
        "no_hit",
        1,
        "if (status == no_intersection) return background_color; // termination: no intersection",
    ),
    line("normal", 1, "n = normal(q);"),
    line(
        "reflect_dir",
        1,
        "r = reflect(d, n);                // R = d − 2(d·N)N",
    ),
    line(
        "refract_dir",
        1,
        "t = refract(d, n);                // Snell; none on total internal reflection",
    ),
    line(
        "local",
        1,
        "local = phong(q, n, r);           // ambient + Σ lit lights (diffuse + specular)",
    ),
    line(
        "shadow",
        2,
        "shadow ray from q to each light: blocked → that light adds nothing",
    ),
    line(
        "trace_r",
        1,
        "reflected = trace(q, r, step+1);  // only when kr > 0",
    ),
    line(
        "trace_t",
        1,
        "refracted = trace(q, t, step+1);  // only when kt > 0 and t exists",
    ),
    line("return", 1, "return(local + kr·reflected + kt·refracted);"),
    line("close", 0, "}"),
];

/// The line with this id.
pub fn line_of(id: &str) -> Option<&'static Line> {
    LINES.iter().find(|l| l.id == id)
}

/// One line as one call executed it.
#[derive(Clone, Debug, PartialEq)]
pub struct Executed {
    /// The line's id in [`LINES`].
    pub line: &'static str,
    /// The node whose call this is, as child indices from the root.
    pub node: Vec<usize>,
    /// `step`: the node's depth.
    pub depth: u32,
    /// Variables and their values at this line, formatted.
    pub vars: Vec<(&'static str, String)>,
    /// The colour summed so far by this call (from `local` on).
    pub sum: Option<Vec3>,
    /// The call returns here.
    pub returns: bool,
}

fn v3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn kind_name(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "primary",
        RayKind::Reflected => "reflected (R)",
        RayKind::Refracted => "refracted (T)",
        RayKind::Shadow => "shadow",
    }
}

/// The lines one call of `trace` executed for `node` (at `path`, in a tree traced with
/// `max_depth`), its children's calls left out; the last one returns.
pub fn node_lines(node: &Node, path: &[usize], max_depth: u32) -> Vec<Executed> {
    let mut out = Vec::new();
    let mut push = |line: &'static str, vars: Vec<(&'static str, String)>, sum, returns| {
        out.push(Executed {
            line,
            node: path.to_vec(),
            depth: node.depth,
            vars,
            sum,
            returns,
        });
    };
    let step = ("step", node.depth.to_string());
    push(
        "signature",
        vec![
            ("ray", kind_name(node.kind).to_string()),
            ("p", v3(node.origin)),
            ("d", v3(node.direction)),
            step.clone(),
        ],
        None,
        false,
    );
    let max = ("max", max_depth.to_string());
    match node.end {
        Some(EndReason::MaxDepth | EndReason::Cutoff | EndReason::Budget) => {
            let why = match node.end {
                Some(EndReason::MaxDepth) => "step > max: true".to_string(),
                Some(EndReason::Cutoff) => "weight below the cutoff (adaptive depth)".into(),
                _ => "the pixel's ray budget is used up".into(),
            };
            push(
                "max_depth",
                vec![step, max, ("test", why), ("returns", v3(node.color))],
                None,
                true,
            );
            return out;
        }
        _ => push(
            "max_depth",
            vec![step.clone(), max, ("test", "step > max: false".into())],
            None,
            false,
        ),
    }
    let status = match (node.end, &node.hit) {
        (Some(EndReason::HitLight), _) => "light_source".to_string(),
        (Some(EndReason::NoHit), _) => "no_intersection".to_string(),
        (_, Some(h)) => format!("surface \"{}\"", h.object),
        _ => "no_intersection".to_string(),
    };
    let mut intersect = vec![("status", status)];
    if let Some(h) = &node.hit {
        intersect.push(("q", v3(h.point)));
        intersect.push(("t", format!("{:.4}", h.t)));
    }
    if let Some(l) = &node.light {
        intersect.push(("light", l.name.clone()));
        intersect.push(("t", format!("{:.4}", l.t)));
    }
    push("intersect", intersect, None, false);
    if node.end == Some(EndReason::HitLight) {
        push("light", vec![("returns", v3(node.color))], None, true);
        return out;
    }
    push("light", Vec::new(), None, false);
    let Some(hit) = &node.hit else {
        push("no_hit", vec![("returns", v3(node.color))], None, true);
        return out;
    };
    push("no_hit", Vec::new(), None, false);
    let n = hit.normal;
    push(
        "normal",
        vec![
            ("n", v3(n)),
            (
                "side",
                if hit.front_face { "outside" } else { "inside" }.into(),
            ),
        ],
        None,
        false,
    );
    let r_child = node
        .children
        .iter()
        .position(|c| c.kind == RayKind::Reflected);
    let t_child = node
        .children
        .iter()
        .position(|c| c.kind == RayKind::Refracted);
    let r_dir = r_child.map_or_else(
        || reflect(node.direction, n).normalize_or_zero(),
        |i| node.children[i].direction,
    );
    push("reflect_dir", vec![("r", v3(r_dir))], None, false);
    let t_text = match t_child {
        Some(i) => v3(node.children[i].direction),
        None if node.total_internal_reflection => "none: total internal reflection".into(),
        None => "not needed (kt = 0)".into(),
    };
    push("refract_dir", vec![("t", t_text)], None, false);
    let local = node.local.map_or(Vec3::ZERO, |l| l.total);
    let mut local_vars = vec![("local", v3(local))];
    if let Some(l) = node.local {
        local_vars.push(("ambient", v3(l.ambient)));
        local_vars.push(("diffuse", v3(l.diffuse)));
        local_vars.push(("specular", v3(l.specular)));
    }
    push("local", local_vars, Some(local), false);
    for s in &node.shadow_rays {
        let state = if s.facing_away || s.behind_surface {
            "light behind the surface".to_string()
        } else if let Some(b) = &s.blocked_by {
            format!("blocked by \"{b}\"")
        } else if s.contributes_nothing {
            "not traced: adds nothing".into()
        } else {
            "lit".into()
        };
        push(
            "shadow",
            vec![
                ("light", s.light.clone()),
                ("shadow", state),
                ("N·L", format!("{:.4}", s.n_dot_l)),
                ("N·H", format!("{:.4}", s.n_dot_h)),
            ],
            Some(local),
            false,
        );
    }
    let kr = node.kr.unwrap_or(Vec3::ZERO);
    let kt = node.kt.unwrap_or(Vec3::ZERO);
    let mut sum = local;
    match r_child {
        Some(i) => {
            let c = node.children[i].color;
            sum += kr * c;
            push(
                "trace_r",
                vec![
                    ("kr", v3(kr)),
                    ("reflected", v3(c)),
                    ("sum so far", v3(sum)),
                ],
                Some(sum),
                false,
            );
        }
        None => push(
            "trace_r",
            vec![("kr", v3(kr)), ("reflected", "not traced (kr = 0)".into())],
            Some(sum),
            false,
        ),
    }
    match t_child {
        Some(i) => {
            let c = node.children[i].color;
            sum += kt * c;
            push(
                "trace_t",
                vec![
                    ("kt", v3(kt)),
                    ("refracted", v3(c)),
                    ("sum so far", v3(sum)),
                ],
                Some(sum),
                false,
            );
        }
        None => {
            let why = if node.total_internal_reflection {
                "not traced: total internal reflection (kt went to kr)"
            } else {
                "not traced (kt = 0)"
            };
            push(
                "trace_t",
                vec![("kt", v3(kt)), ("refracted", why.into())],
                Some(sum),
                false,
            );
        }
    }
    push(
        "return",
        vec![("returns", v3(node.color))],
        Some(node.color),
        true,
    );
    out
}

/// Every line the recursion for `tree` executed, in order. A child's call runs inside its
/// parent's `trace_r` or `trace_t` line: its lines come first, then that line with the colour
/// the call returned.
pub fn walk(tree: &RayTree) -> Vec<Executed> {
    fn go(node: &Node, path: &mut Vec<usize>, max: u32, out: &mut Vec<Executed>) {
        for e in node_lines(node, path, max) {
            let child = match e.line {
                "trace_r" => node
                    .children
                    .iter()
                    .position(|c| c.kind == RayKind::Reflected),
                "trace_t" => node
                    .children
                    .iter()
                    .position(|c| c.kind == RayKind::Refracted),
                _ => None,
            };
            if let Some(i) = child {
                path.push(i);
                go(&node.children[i], path, max, out);
                path.pop();
            }
            out.push(e);
        }
    }
    let mut out = Vec::new();
    go(
        &tree.root,
        &mut Vec::new(),
        tree.settings.max_depth,
        &mut out,
    );
    out
}

/// The line to highlight for the node at `path`: where its call returns (the termination
/// condition that ended it, or the final `return`). `None` if the tree has no such node.
pub fn current_line(tree: &RayTree, path: &[usize]) -> Option<Executed> {
    let mut node = &tree.root;
    for &i in path {
        node = node.children.get(i)?;
    }
    node_lines(node, path, tree.settings.max_depth).pop()
}
