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

/// What `raytree render` reports of one run: `--stats-json` writes it (fields in alphabetical
/// order, one fixed order for the programs that read it), and the summary lines are its
/// [`RunReport::lines`].
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// Threads of rayon's global pool, which builds the accelerator.
    pub build_threads: usize,
    pub load_secs: f64,
    pub memory: MemoryStats,
    pub mrays_per_sec: f64,
    pub spheres: usize,
    pub stats: RenderStats,
    pub triangles: usize,
    /// Primitives the accelerator dropped (non-finite, zero area) and its depth, for the
    /// memory line.
    #[serde(skip)]
    pub skipped: usize,
    #[serde(skip)]
    pub bvh_depth: Option<usize>,
    #[serde(skip)]
    pub max_depth: u32,
}

impl RunReport {
    /// The report of a render by `tracer` that took `load_secs` to load.
    pub fn new(tracer: &Tracer, stats: RenderStats, load_secs: f64) -> Self {
        let memory = MemoryStats::of(tracer);
        Self {
            build_threads: rayon::current_num_threads(),
            load_secs,
            memory,
            mrays_per_sec: stats.mrays_per_sec(),
            spheres: memory.spheres,
            stats,
            triangles: memory.triangles,
            skipped: tracer.accel.skipped_prims(),
            bvh_depth: tracer.accel.bvh_depth(),
            max_depth: tracer.scene.render.max_depth,
        }
    }

    /// The summary printed after a render: size and settings, rays by kind, times, and with
    /// `memory` the geometry's memory.
    pub fn lines(&self, output: &str, memory: bool) -> Vec<String> {
        let (s, r, m) = (&self.stats, &self.stats.rays, &self.memory);
        let mut lines = vec![
            format!(
                "wrote {output} ({}x{}, {} spp, max depth {}, {} threads, accel {:?})",
                s.width,
                s.height,
                s.samples,
                self.max_depth,
                s.threads,
                s.accel.unwrap_or_default(),
            ),
            format!(
                "rays: {} primary, {} reflected, {} refracted, {} shadow, {} in all",
                r.primary,
                r.reflected,
                r.refracted,
                r.shadow,
                r.total()
            ),
            format!(
                "time: load {:.3} s, build {:.3} s, render {:.3} s, {:.2} Mrays/s",
                self.load_secs, s.build_secs, s.render_secs, self.mrays_per_sec
            ),
        ];
        if memory {
            lines.push(format!(
                "memory: accelerator {} B + scene records {} B for {} triangles and {} spheres = \
                 {:.1} B per primitive{} ({} skipped{})",
                m.accel_bytes,
                m.scene_geometry_bytes,
                m.triangles,
                m.spheres,
                m.bytes_per_primitive(),
                m.bytes_per_triangle
                    .map(|b| format!(", {b:.1} B per triangle"))
                    .unwrap_or_default(),
                self.skipped,
                self.bvh_depth
                    .map(|d| format!(", BVH depth {d}"))
                    .unwrap_or_default(),
            ));
        }
        lines
    }
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
