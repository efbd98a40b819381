//! Data parallelism over the CPU's cores (the CPU twins, the BSDF's albedo table): rayon
//! natively; on wasm32, which has no threads, the same calls run one after another on the
//! calling thread. `use crate::par::prelude::*` in place of `use rayon::prelude::*`.
//!
//! The sequential twin offers only what the crate uses: `into_par_iter`, `par_iter`,
//! `with_min_len`, `map`, `fold`, `reduce` and `collect`, with rayon's signatures.

#[cfg(not(target_arch = "wasm32"))]
pub mod prelude {
    pub use rayon::prelude::*;
}

#[cfg(target_arch = "wasm32")]
pub mod prelude {
    pub use super::sequential::{IntoParallelIterator, IntoParallelRefIterator};
}

/// Rayon's iterator calls on one thread, in order (compiled natively for its test).
#[cfg(any(target_arch = "wasm32", test))]
mod sequential {
    /// An iterator run in order on the calling thread, with rayon's method signatures.
    pub struct Sequential<I>(I);

    /// `into_par_iter` on anything iterable.
    pub trait IntoParallelIterator: IntoIterator + Sized {
        fn into_par_iter(self) -> Sequential<Self::IntoIter> {
            Sequential(self.into_iter())
        }
    }
    impl<T: IntoIterator> IntoParallelIterator for T {}

    /// `par_iter` on a slice.
    pub trait IntoParallelRefIterator<T> {
        fn par_iter(&self) -> Sequential<std::slice::Iter<'_, T>>;
    }
    impl<T> IntoParallelRefIterator<T> for [T] {
        fn par_iter(&self) -> Sequential<std::slice::Iter<'_, T>> {
            Sequential(self.iter())
        }
    }

    impl<I: Iterator> Sequential<I> {
        /// Rayon's splitting hint: nothing to split here.
        pub fn with_min_len(self, _min: usize) -> Self {
            self
        }

        pub fn map<R, F: FnMut(I::Item) -> R>(self, f: F) -> Sequential<std::iter::Map<I, F>> {
            Sequential(self.0.map(f))
        }

        /// Rayon folds each split into its own accumulator; here there is one split.
        pub fn fold<T, Id: Fn() -> T, F: FnMut(T, I::Item) -> T>(
            self,
            identity: Id,
            fold: F,
        ) -> Sequential<std::iter::Once<T>> {
            Sequential(std::iter::once(self.0.fold(identity(), fold)))
        }

        pub fn reduce<Id: Fn() -> I::Item, F: FnMut(I::Item, I::Item) -> I::Item>(
            self,
            identity: Id,
            reduce: F,
        ) -> I::Item {
            self.0.fold(identity(), reduce)
        }

        pub fn collect<C: FromIterator<I::Item>>(self) -> C {
            self.0.collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::sequential::{IntoParallelIterator, IntoParallelRefIterator};

    /// The sequential twin answers as the iterators it stands for.
    #[test]
    fn sequential_runs_the_calls_in_order() {
        let v: Vec<u64> = (0..1000u64).into_par_iter().map(|i| i * i).collect();
        assert_eq!(v, (0..1000u64).map(|i| i * i).collect::<Vec<_>>());
        let sum = v.par_iter().with_min_len(16).fold(|| 0u64, |s, x| s + x).reduce(|| 0, |a, b| a + b);
        assert_eq!(sum, v.iter().sum::<u64>());
    }
}
