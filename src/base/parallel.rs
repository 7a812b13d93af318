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
