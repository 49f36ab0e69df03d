//! The memory budget (docs/reliability.md): sizes a file may ask for are checked against an
//! estimate of the memory they need before anything of that size is allocated, so a hostile or
//! mistyped scene gets a sentence instead of an out-of-memory kill. The loader (meshes), the batch
//! render and the viewer's buffers all ask this one budget.

/// Peak bytes per pixel of `render::render` and an export: the tile sums of every tile held until
/// the image is assembled (12), the image (12), and the encoder's copy (3 for PNG, about 12 for EXR
/// written to memory first), rounded up.
pub const BATCH_BYTES_PER_PIXEL: u64 = 40;

/// Bytes per pixel of the viewer: the session's running sums (12), the film (12), the image-mode
/// facts (24), the display buffer (16), the GPU texture (16) and tiles in flight, rounded up.
pub const VIEWER_BYTES_PER_PIXEL: u64 = 96;

/// Peak bytes per triangle while an OBJ is read and accelerated: tobj's face list (up to 104
/// bytes a face, doubled by vector growth), its index map and index list, the scene's triangle
/// (44), the accelerator's copy and the BVH build. Measured: a 1M-triangle OBJ of random
/// triangles peaks at about 410 bytes per triangle (`/usr/bin/time -v raytree render`).
pub const TRIANGLE_BYTES: u64 = 450;

/// Bytes per OBJ vertex while reading (tobj's position list and the mesh's copy), rounded up.
pub const VERTEX_BYTES: u64 = 32;

/// The budget used when the machine's memory is unknown.
pub const FALLBACK_MEMORY_LIMIT: u64 = 16 << 30;

/// How much memory a render or a load may plan to use, and where that number came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryLimit {
    pub bytes: u64,
    /// "three quarters of this machine's 24.0 GiB", "RAYTREE_MEMORY_LIMIT=512", ...
    pub source: String,
}

impl MemoryLimit {
    /// Refuses `estimate` bytes for `what` ("a 16384x16384 render") when over the limit.
    pub fn check(&self, what: impl Into<String>, estimate: u64) -> Result<(), MemoryError> {
        if estimate <= self.bytes {
            return Ok(());
        }
        Err(MemoryError {
            what: what.into(),
            estimate,
            limit: self.clone(),
        })
    }
}

/// Something refused because its memory estimate is over the limit: one sentence.
#[derive(Clone, Debug, thiserror::Error)]
#[error(
    "{what} would need about {}, more than the memory limit of {} ({})",
    format_bytes(*estimate),
    format_bytes(limit.bytes),
    limit.source
)]
pub struct MemoryError {
    pub what: String,
    pub estimate: u64,
    pub limit: MemoryLimit,
}

/// The memory budget: `RAYTREE_MEMORY_LIMIT` (a whole number of MiB) if set, else three
/// quarters of the machine's memory (Linux `/proc/meminfo`), else 16 GiB. Read once.
pub fn memory_limit() -> MemoryLimit {
    static LIMIT: std::sync::OnceLock<MemoryLimit> = std::sync::OnceLock::new();
    LIMIT
        .get_or_init(|| {
            memory_limit_from(std::env::var("RAYTREE_MEMORY_LIMIT").ok(), machine_memory())
        })
        .clone()
}

/// [`memory_limit`] from its inputs: the variable's value and the machine's memory in bytes.
pub fn memory_limit_from(variable: Option<String>, machine: Option<u64>) -> MemoryLimit {
    const HOW: &str = "set RAYTREE_MEMORY_LIMIT to a number of MiB to change it";
    let default = || match machine {
        Some(total) => MemoryLimit {
            bytes: total / 4 * 3,
            source: format!(
                "three quarters of this machine's {}; {HOW}",
                format_bytes(total)
            ),
        },
        None => MemoryLimit {
            bytes: FALLBACK_MEMORY_LIMIT,
            source: format!("the default, as this machine's memory is unknown; {HOW}"),
        },
    };
    match variable {
        None => default(),
        Some(text) => match text.trim().parse::<u64>() {
            Ok(mib) if mib > 0 => MemoryLimit {
                bytes: mib.saturating_mul(1 << 20),
                source: format!("set by RAYTREE_MEMORY_LIMIT={mib}"),
            },
            // A typo must not silently lift or lower the limit: say that it was ignored.
            _ => {
                let mut limit = default();
                limit.source = format!(
                    "{}; RAYTREE_MEMORY_LIMIT=\"{}\" is not a whole number of MiB and was ignored",
                    limit.source.split(';').next().unwrap_or_default(),
                    text.escape_debug()
                );
                limit
            }
        },
    }
}

/// Total memory from `/proc/meminfo` (Linux), in bytes.
fn machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Peak memory of a `width × height` batch render and its export.
pub fn batch_memory_estimate(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * BATCH_BYTES_PER_PIXEL
}

/// Memory of the viewer's buffers for a `width × height` image.
pub fn viewer_memory_estimate(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * VIEWER_BYTES_PER_PIXEL
}

/// Peak memory of reading an OBJ of `text_bytes` with `vertices` vertices and `triangles`
/// triangles (after triangulation) and accelerating it.
pub fn mesh_memory_estimate(text_bytes: u64, vertices: u64, triangles: u64) -> u64 {
    text_bytes
        .saturating_add(vertices.saturating_mul(VERTEX_BYTES))
        .saturating_add(triangles.saturating_mul(TRIANGLE_BYTES))
}

/// `1.5 GiB`, `12.0 MiB`, `512 bytes`.
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if bytes >= size {
            return format!("{:.1} {unit}", bytes as f64 / size as f64);
        }
    }
    format!("{bytes} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_limit_comes_from_the_variable_or_the_machine() {
        let l = memory_limit_from(Some("512".into()), Some(8 << 30));
        assert_eq!(
            (l.bytes, l.source.as_str()),
            (512 << 20, "set by RAYTREE_MEMORY_LIMIT=512")
        );
        let l = memory_limit_from(None, Some(8 << 30));
        assert_eq!(l.bytes, 6 << 30);
        assert_eq!(
            l.source,
            "three quarters of this machine's 8.0 GiB; set RAYTREE_MEMORY_LIMIT to a number of \
             MiB to change it"
        );
        let l = memory_limit_from(Some("lots".into()), None);
        assert_eq!(l.bytes, FALLBACK_MEMORY_LIMIT);
        assert!(
            l.source.contains("\"lots\" is not a whole number of MiB"),
            "{}",
            l.source
        );
        assert!(
            l.check("a render", batch_memory_estimate(16384, 16384))
                .is_ok()
        );
        let l = memory_limit_from(Some("1024".into()), None);
        let e = l
            .check("a 16384x16384 render", batch_memory_estimate(16384, 16384))
            .expect_err("10 GiB is over 1 GiB")
            .to_string();
        assert_eq!(
            e,
            "a 16384x16384 render would need about 10.0 GiB, more than the memory limit of \
             1.0 GiB (set by RAYTREE_MEMORY_LIMIT=1024)"
        );
    }
}
