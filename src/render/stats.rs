//! The figures of a render: its time and rays ([`RenderStats`]) and the memory its tracer holds
//! ([`MemoryStats`]), one owner for what `raytree render --stats` prints and `--stats-json`
//! writes.

use serde::Serialize;

use crate::accel::AccelKind;
use crate::scene::{Sphere, Triangle};
use crate::trace::{RayCounts, Tracer};

/// Figures of one render.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RenderStats {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub threads: usize,
    /// The accelerator actually used (`auto` resolved).
    pub accel: Option<AccelKind>,
    pub rays: RayCounts,
    pub build_secs: f64,
    pub render_secs: f64,
}

impl RenderStats {
    /// Millions of rays (all kinds) per second of the render phase.
    pub fn mrays_per_sec(&self) -> f64 {
        self.rays.total() as f64 / self.render_secs.max(1e-9) / 1e6
    }
}

/// Memory figures of a tracer, for `--stats`, `--stats-json` and the benchmarks. The JSON holds
/// the four serialized fields (the peer benchmark reads them); the primitive counts stay out of
/// it, as the JSON has them at its top level.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct MemoryStats {
    /// The process's peak resident set (`VmHWM` of `/proc/self/status`); `None` where that
    /// file does not exist.
    pub peak_bytes: Option<u64>,
    /// The scene's spheres and triangles as the scene stores them.
    pub scene_geometry_bytes: u64,
    /// The accelerator, its own compact copy of the primitives included.
    pub accel_bytes: u64,
    /// `(scene_geometry_bytes + accel_bytes) / triangles`: what tracing costs per triangle
    /// (the spheres' few bytes included); `None` without triangles.
    pub bytes_per_triangle: Option<f64>,
    #[serde(skip)]
    pub triangles: usize,
    #[serde(skip)]
    pub spheres: usize,
}

impl MemoryStats {
    pub fn of(tracer: &Tracer) -> Self {
        let scene = &tracer.scene;
        let (triangles, spheres) = (scene.triangles.len(), scene.spheres.len());
        let scene_geometry_bytes =
            (triangles * size_of::<Triangle>() + spheres * size_of::<Sphere>()) as u64;
        let accel_bytes = tracer.accel.memory_bytes() as u64;
        Self {
            peak_bytes: peak_memory_bytes(),
            scene_geometry_bytes,
            accel_bytes,
            bytes_per_triangle: (triangles > 0)
                .then(|| (scene_geometry_bytes + accel_bytes) as f64 / triangles as f64),
            triangles,
            spheres,
        }
    }

    /// `(scene_geometry_bytes + accel_bytes) / (triangles + spheres)`: what tracing costs per
    /// primitive of either kind (0 primitives count as 1).
    pub fn bytes_per_primitive(&self) -> f64 {
        (self.scene_geometry_bytes + self.accel_bytes) as f64
            / (self.triangles + self.spheres).max(1) as f64
    }
}

/// The process's peak resident set in bytes (`VmHWM`), where `/proc/self/status` has it.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::scene::builtin::load_builtin;
    use crate::trace::TraceSettings;

    #[test]
    fn both_denominators_share_one_numerator() {
        let scene = load_builtin("default").expect("a built-in scene");
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let m = MemoryStats::of(&tracer);
        assert!(m.triangles > 0 && m.spheres > 0, "{m:?}");
        let bytes = (m.scene_geometry_bytes + m.accel_bytes) as f64;
        assert_eq!(m.bytes_per_triangle, Some(bytes / m.triangles as f64));
        assert_eq!(
            m.bytes_per_primitive(),
            bytes / (m.triangles + m.spheres) as f64
        );
        let json = serde_json::to_value(m).expect("serializes");
        let mut keys: Vec<&str> = json
            .as_object()
            .expect("an object")
            .keys()
            .map(String::as_str)
            .collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "accel_bytes",
                "bytes_per_triangle",
                "peak_bytes",
                "scene_geometry_bytes"
            ]
        );
    }
}
