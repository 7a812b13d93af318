//! Work on all cores natively (rayon); in order on wasm32 (a web worker is single-threaded).

/// `f(0..n)` on all cores (natively, rayon's pool), in index order of the result.
#[cfg(not(target_arch = "wasm32"))]
pub fn par_map<R: Send>(n: usize, f: &(dyn Fn(usize) -> R + Sync)) -> Vec<R> {
    use rayon::prelude::*;
    (0..n).into_par_iter().map(f).collect()
}

/// `f(0..n)` in order (a wasm worker is single-threaded).
#[cfg(target_arch = "wasm32")]
pub fn par_map<R: Send>(n: usize, f: &(dyn Fn(usize) -> R + Sync)) -> Vec<R> {
    (0..n).map(f).collect()
}

/// `f(i, item)` for every item of `items` (taken by value) on all cores natively, in order on
/// wasm32; the results in the items' order.
pub fn par_map_owned<T: Send, R: Send>(
    items: Vec<T>,
    f: &(dyn Fn(usize, T) -> R + Sync),
) -> Vec<R> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        use rayon::prelude::*;
        items
            .into_par_iter()
            .enumerate()
            .map(|(i, t)| f(i, t))
            .collect()
    }
    #[cfg(target_arch = "wasm32")]
    {
        items
            .into_iter()
            .enumerate()
            .map(|(i, t)| f(i, t))
            .collect()
    }
}

/// Runs two computations, on two threads natively (wasm workers are single-threaded).
pub fn both<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        rayon::join(a, b)
    }
    #[cfg(target_arch = "wasm32")]
    {
        (a(), b())
    }
}

/// Items per call of [`in_runs`].
pub const RUN: usize = 4_096;

/// `f(range)` for consecutive ranges of at most [`RUN`] items covering `0..n`, in order.
///
/// For the long passes of the preparation (over every facet or corner), in the page: the
/// engine first runs a function as quickly compiled code and compiles it well in the
/// background once it has done enough work, but a call already running keeps the quick code
/// to its end, so one long loop in one call runs the quick code throughout (the first
/// preparation of a 1M-facet part took 0.62 s in Node against 0.39 s once compiled). Each
/// range is a call of `f` through a pointer, which the compiler does not inline into a loop
/// here: the later ranges run the well-compiled code. Natively it costs one call per range.
#[inline(never)]
pub fn in_runs(n: usize, f: &mut dyn FnMut(std::ops::Range<usize>)) {
    let mut at = 0;
    while at < n {
        let end = n.min(at + RUN);
        f(at..end);
        at = end;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owned_items_are_mapped_once_each_in_their_order() {
        let items: Vec<String> = (0..1000).map(|i| format!("item {i}")).collect();
        let out = par_map_owned(items, &|i, s| (i, s.len(), s));
        assert_eq!(out.len(), 1000);
        for (k, (i, len, s)) in out.into_iter().enumerate() {
            assert_eq!((i, s.clone()), (k, format!("item {k}")));
            assert_eq!(len, s.len());
        }
    }

    #[test]
    fn runs_cover_every_index_once_in_order_and_none_is_longer_than_a_run() {
        for n in [0, 1, RUN - 1, RUN, RUN + 1, 3 * RUN + 5] {
            let mut seen = Vec::new();
            let mut longest = 0;
            in_runs(n, &mut |r| {
                longest = longest.max(r.len());
                assert!(!r.is_empty(), "an empty run for n = {n}");
                seen.extend(r);
            });
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "n = {n}");
            assert!(longest <= RUN);
            assert_eq!(longest, n.min(RUN));
        }
    }
}
