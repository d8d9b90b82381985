//! Data parallelism: rayon with the default feature `parallel`; without it the same
//! loops run in order, for a vehicle's computer with one core or no threads. Every
//! parallel loop of the crate works on fixed chunks and combines their results in chunk
//! order (or by a maximum, which no order changes), so both give the same bits.

#[cfg(feature = "parallel")]
pub(crate) use rayon::prelude::*;

#[cfg(not(feature = "parallel"))]
pub(crate) use sequential::*;

/// The largest of `value(i)` for i in 0..len (NaNs ignored, as by `f64::max`), by chunks
/// of `chunk`.
pub(crate) fn max_over(len: usize, chunk: usize, value: impl Fn(usize) -> f64 + Sync) -> f64 {
    let maxima: Vec<f64> = (0..len.div_ceil(chunk))
        .into_par_iter()
        .map(|c| (c * chunk..((c + 1) * chunk).min(len)).map(&value).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    maxima.into_iter().fold(f64::NEG_INFINITY, f64::max)
}

/// rayon's names for the standard library's sequential iterators.
#[cfg(not(feature = "parallel"))]
mod sequential {
    pub(crate) trait ParSlice<T> {
        fn par_iter(&self) -> std::slice::Iter<'_, T>;
        fn par_chunks(&self, n: usize) -> std::slice::Chunks<'_, T>;
    }

    impl<T> ParSlice<T> for [T] {
        fn par_iter(&self) -> std::slice::Iter<'_, T> {
            self.iter()
        }
        fn par_chunks(&self, n: usize) -> std::slice::Chunks<'_, T> {
            self.chunks(n)
        }
    }

    pub(crate) trait ParSliceMut<T> {
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T>;
        fn par_chunks_mut(&mut self, n: usize) -> std::slice::ChunksMut<'_, T>;
    }

    impl<T> ParSliceMut<T> for [T] {
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T> {
            self.iter_mut()
        }
        fn par_chunks_mut(&mut self, n: usize) -> std::slice::ChunksMut<'_, T> {
            self.chunks_mut(n)
        }
    }

    pub(crate) trait IntoParallelIterator: IntoIterator + Sized {
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }

    impl<I: IntoIterator> IntoParallelIterator for I {}
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The maximum against a plain fold, NaNs ignored, over lengths around the chunk.
    #[test]
    fn max_over_is_the_maximum() {
        for len in [0, 1, 7, 8, 9, 100] {
            let value = |i: usize| if i % 5 == 3 { f64::NAN } else { ((i * 37) % 11) as f64 - 4.0 };
            let expected = (0..len).map(value).fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(max_over(len, 8, value), expected, "len {len}");
        }
    }
}
