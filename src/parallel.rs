//! Data parallelism: rayon natively, a plain loop in wasm (one thread in
//! the worker). The one place outside `web/` that looks at the target: the
//! results are identical either way because every caller maps independent
//! items and writes them back in order.

/// `out[k] = f(items[k])` for every `k`, in parallel where threads exist.
pub fn map_into<T: Send, U: Sync>(
    items: &[U],
    out: &mut Vec<T>,
    f: impl Fn(&U) -> T + Sync + Send,
) {
    out.clear();
    #[cfg(not(target_arch = "wasm32"))]
    {
        use rayon::prelude::*;
        if items.len() >= 1024 {
            items.par_iter().map(f).collect_into_vec(out);
            return;
        }
    }
    out.extend(items.iter().map(f));
}
