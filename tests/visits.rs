//! `Tracer::visits_of` (the accelerator made visible): replaying a ray-tree node's
//! query gives the node's recorded hit, and its shadow rays the verdicts the tree shows.

use std::sync::Arc;

use raytree::accel::{AccelKind, Visits};
use raytree::ray_tree::{Node, pixel_tree};
use raytree::scene::load_builtin;
use raytree::trace::{EndReason, TraceSettings, Tracer, VisitQuery};

fn nodes(node: &Node) -> Vec<&Node> {
    let mut out = vec![node];
    for c in &node.children {
        out.extend(nodes(c));
    }
    out
}

/// Every node of the glass sphere's tree, replayed through every accelerator: the closest hit
/// is the node's (same `t`, same object), a miss stays a miss, and each shadow ray is blocked
/// exactly when the tree says so, no nearer than the tree's (closest) blocker.
#[test]
fn replayed_queries_give_the_glass_trees_hits() {
    let scene = Arc::new(load_builtin("glass").expect("glass"));
    let (w, h) = (scene.render.width, scene.render.height);
    for accel in [
        AccelKind::Auto,
        AccelKind::None,
        AccelKind::Grid,
        AccelKind::Bvh,
    ] {
        let settings = TraceSettings {
            accel,
            ..TraceSettings::default()
        };
        let tracer = Tracer::new(scene.clone(), settings);
        // Through the glass sphere (the same pixel tests/hostile.rs uses).
        let tree = pixel_tree(&tracer, w * 27 / 100, h * 55 / 100).expect("a tree");
        let all = nodes(&tree.root);
        assert!(
            all.len() > 4,
            "the pixel misses the glass: {} nodes",
            all.len()
        );
        let mut hits = 0;
        for (i, node) in all.iter().enumerate() {
            let v: Visits = tracer.visits_of(node.origin, node.direction, VisitQuery::Closest);
            match (&node.hit, node.end) {
                (Some(recorded), _) => {
                    let hit = v.hit.expect("the replay hits");
                    assert_eq!(hit.t, recorded.t, "{accel:?} node {i}");
                    let object = tracer
                        .scene
                        .hit_name(tracer.object_of(hit.prim), Some(hit.prim));
                    assert_eq!(object, recorded.object, "{accel:?} node {i}");
                    assert!(v.prims.contains(&hit.prim));
                    if tracer.accel.kind() != AccelKind::None {
                        assert!(!v.boxes.is_empty(), "{accel:?} node {i}");
                    }
                    hits += 1;
                }
                (None, Some(EndReason::NoHit)) => assert_eq!(v.hit, None, "{accel:?} {i}"),
                (None, Some(EndReason::HitLight)) => {
                    let light = node.light.as_ref().expect("the light");
                    assert!(v.hit.is_none_or(|h| h.t >= light.t), "{accel:?} {i}");
                }
                // Not traced (depth, cutoff, budget): nothing to compare.
                _ => {}
            }
            for (light, shadow) in node.shadow_rays.iter().enumerate() {
                let s = tracer.visits_of(node.origin, node.direction, VisitQuery::Shadow { light });
                assert_eq!(
                    s.hit.is_some(),
                    shadow.blocked_by.is_some(),
                    "{accel:?} node {i} light {light}"
                );
                if let (Some(h), Some(at)) = (s.hit, shadow.blocked_at) {
                    assert!(h.t >= at, "{accel:?} node {i} light {light}");
                }
                if shadow.facing_away {
                    assert_eq!(s, Visits::default());
                }
            }
        }
        assert!(hits > 3, "{accel:?}: {hits} hits");
        // Out of range or without a hit: nothing.
        let missing = VisitQuery::Shadow { light: usize::MAX };
        let root = &tree.root;
        assert_eq!(
            tracer.visits_of(root.origin, root.direction, missing),
            Visits::default()
        );
    }
}
