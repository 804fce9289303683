//! Union-find over `0..n` with path halving, for grouping triangles into shells and regions and faces into plates.
//! The root of a set is its smallest member, so sets are numbered the same whatever the order of the unions.
//! Amortised almost O(1) per operation.

/// The root (smallest member) of `x`'s set.
pub(crate) fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Joins the sets of `a` and `b`.
pub(crate) fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}
