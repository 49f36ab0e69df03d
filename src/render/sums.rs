//! The batch render's per-pixel sums: one buffer for every tile of a render, kept by the tracer
//! from one render to the next.

use glam::Vec3;

use crate::trace::Tracer;

/// Memory for a batch render's per-pixel sums: anonymous pages straight from the kernel,
/// zeroed, with transparent huge pages asked for where the system offers them on request
/// (Linux's default `madvise` mode; Embree asks the same for its large allocations). Only
/// the whole 2 MiB pages inside the mapping can be huge: a 640×480 render's 3.7 MB holds one,
/// so its first frame takes one 2 MiB fault and about 450 of 4 KiB instead of 900 (the
/// bench's `--opaque` 80k first frame, 12 alternating runs: 27.9 → 26.4 ms). Aligning the
/// buffer so that both of its pages are huge was measured no faster (docs/performance.md). The
/// warm frames reuse the buffer. The allocator's memory where mapping fails.
pub(crate) enum SumsBuffer {
    Mapped(memmap2::MmapMut),
    Heap(Vec<[f32; 3]>),
}

impl SumsBuffer {
    /// Room for `n` sums, all zero.
    fn fresh(n: usize) -> Self {
        let bytes = n * size_of::<[f32; 3]>();
        match memmap2::MmapMut::map_anon(bytes.max(1)) {
            Ok(map) => {
                // A hint: where it is refused (`never`, other systems), 4 KiB pages it is.
                #[cfg(target_os = "linux")]
                let _ = map.advise(memmap2::Advice::HugePage);
                Self::Mapped(map)
            }
            Err(_) => Self::Heap(vec![[0.0; 3]; n]),
        }
    }

    /// How many sums it holds.
    fn len(&self) -> usize {
        match self {
            Self::Mapped(map) => map.len() / size_of::<[f32; 3]>(),
            Self::Heap(v) => v.len(),
        }
    }

    /// The first `n` sums as `Vec3`s (`n` at most [`SumsBuffer::len`]).
    pub(crate) fn vec3s_mut(&mut self, n: usize) -> &mut [Vec3] {
        match self {
            Self::Mapped(map) => bytemuck::cast_slice_mut(&mut map[..n * size_of::<[f32; 3]>()]),
            Self::Heap(v) => bytemuck::cast_slice_mut(&mut v[..n]),
        }
    }

    /// Room for `n` sums for a batch render of `tracer` ([`SumsBuffer::vec3s_mut`]): the buffer
    /// of its last render (still holding its values: the caller zeroes each tile's part where
    /// its worker starts it) when it is large enough, otherwise fresh zeroed pages, which the
    /// workers fault in tile by tile, in parallel, instead of one thread writing it all before
    /// the first tile. Give it back with [`SumsBuffer::keep`].
    pub(crate) fn take(tracer: &Tracer, n: usize) -> Self {
        let kept = tracer
            .kept_sums
            .lock()
            .ok()
            .and_then(|mut kept| kept.take())
            .and_then(|kept| kept.downcast::<SumsBuffer>().ok())
            .filter(|kept| kept.len() >= n);
        kept.map_or_else(|| SumsBuffer::fresh(n), |kept| *kept)
    }

    /// Keeps the buffer in `tracer` for its next batch render ([`SumsBuffer::take`]).
    pub(crate) fn keep(self, tracer: &Tracer) {
        if let Ok(mut kept) = tracer.kept_sums.lock() {
            *kept = Some(Box::new(self));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::TraceSettings;

    /// Fresh sums are zero, hold what is written, and come back from `keep` while they
    /// are large enough; a larger render gets a fresh, zeroed buffer; an empty one works.
    #[test]
    fn sums_buffers_are_zeroed_kept_and_replaced() {
        let scene = std::sync::Arc::new(
            crate::scene::builtin::load_builtin("default").expect("built-in scene"),
        );
        let tracer = Tracer::new(scene, TraceSettings::default());
        let mut empty = SumsBuffer::take(&tracer, 0);
        assert!(empty.vec3s_mut(0).is_empty());
        let mut sums = SumsBuffer::take(&tracer, 1000);
        assert!(sums.len() >= 1000);
        assert!(sums.vec3s_mut(1000).iter().all(|v| *v == Vec3::ZERO));
        sums.vec3s_mut(1000)[999] = Vec3::new(1.0, 2.0, 3.0);
        sums.keep(&tracer);
        // Smaller: the kept buffer, values and all (the render zeroes each tile's part).
        let mut again = SumsBuffer::take(&tracer, 1000);
        assert_eq!(again.vec3s_mut(1000)[999], Vec3::new(1.0, 2.0, 3.0));
        again.keep(&tracer);
        let bigger = 1_000_000;
        let mut fresh = SumsBuffer::take(&tracer, bigger);
        assert!(fresh.vec3s_mut(bigger).iter().all(|v| *v == Vec3::ZERO));
        fresh.vec3s_mut(bigger)[bigger - 1] = Vec3::ONE;
    }
}
