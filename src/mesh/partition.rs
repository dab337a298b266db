//! Deterministic partition of the mesh across MPI ranks along a Morton curve.

use super::Mesh;

/// Bits per axis of the Morton key.
const BITS: u32 = 21;

/// Tet and node ownership across ranks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Rank owning each tet.
    pub tet_rank: Vec<u32>,
    /// Owner of each node: the lowest rank among the tets containing it.
    pub node_rank: Vec<u32>,
    /// All nodes sorted by (owner rank, Morton key of coordinates, id).
    pub node_order: Vec<u32>,
}

/// Spreads the low 21 bits of `v` so that bit `i` moves to bit `3 i`.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// 63-bit Morton (Z-order) key of three 21-bit integer coordinates.
pub fn morton3(q: [u32; 3]) -> u64 {
    spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2
}

/// Morton key of a point, quantised in the box `[lo, hi]`.
fn point_key(p: &[f64; 3], lo: &[f64; 3], hi: &[f64; 3]) -> u64 {
    let max = f64::from((1u32 << BITS) - 1);
    morton3([0, 1, 2].map(|c| {
        let s = (p[c] - lo[c]) / (hi[c] - lo[c]);
        (s.clamp(0.0, 1.0) * max) as u32
    }))
}

/// Indices `0..keys.len()` sorted by `(key, index)`.
fn sorted_by_key(keys: &[u64]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..keys.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (keys[i as usize], i));
    order
}

/// All nodes of `mesh` in Morton order of their coordinates (ties by id).
pub fn morton_order(mesh: &Mesh) -> Vec<u32> {
    let (lo, hi) = mesh.spec.bounds();
    let keys: Vec<u64> = mesh.nodes.iter().map(|p| point_key(p, &lo, &hi)).collect();
    sorted_by_key(&keys)
}

/// Split `n` items over `parts` in equal blocks of ceil(n / parts), the last the remainder
/// (later parts may be empty): block r is `b[r]..b[r + 1]` of the returned `parts + 1`
/// bounds. The layout ScaLAPACK's block-cyclic matrices require of the ranks' rows.
pub fn equal_blocks(n: usize, parts: usize) -> Vec<usize> {
    let chunk = n.div_ceil(parts);
    (0..=parts).map(|r| (r * chunk).min(n)).collect()
}

/// Splits the mesh into `nranks` parts: tets ordered along the Morton curve
/// of their centroids and cut into contiguous chunks of equal size (within
/// one); nodes owned by the lowest rank touching them. Pure function of the
/// mesh, hence identical on every rank.
pub fn partition(mesh: &Mesh, nranks: usize) -> Partition {
    assert!(nranks > 0, "partition: nranks must be > 0");
    let (lo, hi) = mesh.spec.bounds();
    let tet_keys: Vec<u64> = (0..mesh.tets.len())
        .map(|t| {
            let p = mesh.tet_corners(t);
            let c = [0, 1, 2].map(|k| 0.25 * (p[0][k] + p[1][k] + p[2][k] + p[3][k]));
            point_key(&c, &lo, &hi)
        })
        .collect();
    let n = mesh.tets.len();
    let mut tet_rank = vec![0u32; n];
    for (pos, &t) in sorted_by_key(&tet_keys).iter().enumerate() {
        tet_rank[t as usize] = (pos * nranks / n.max(1)) as u32;
    }
    let mut node_rank = vec![u32::MAX; mesh.nodes.len()];
    for (t, q) in mesh.tets.iter().enumerate() {
        for &v in q {
            node_rank[v as usize] = node_rank[v as usize].min(tet_rank[t]);
        }
    }
    let node_keys: Vec<u64> = mesh.nodes.iter().map(|p| point_key(p, &lo, &hi)).collect();
    let mut node_order: Vec<u32> = (0..mesh.nodes.len() as u32).collect();
    node_order.sort_unstable_by_key(|&i| (node_rank[i as usize], node_keys[i as usize], i));
    Partition { tet_rank, node_rank, node_order }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_blocks_are_ceil_sized_with_the_remainder_last() {
        assert_eq!(equal_blocks(10, 4), vec![0, 3, 6, 9, 10]);
        assert_eq!(equal_blocks(3237, 2), vec![0, 1619, 3237]);
        assert_eq!(equal_blocks(5, 4), vec![0, 2, 4, 5, 5]);
        assert_eq!(equal_blocks(7, 1), vec![0, 7]);
    }

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton3([1, 0, 0]), 1);
        assert_eq!(morton3([0, 1, 0]), 2);
        assert_eq!(morton3([0, 0, 1]), 4);
        assert_eq!(morton3([3, 0, 0]), 0b1001);
        assert_eq!(morton3([0x1f_ffff; 3]), (1u64 << 63) - 1);
    }

    #[test]
    fn sorted_by_key_is_stable_on_ties() {
        assert_eq!(sorted_by_key(&[5, 1, 5, 0]), vec![3, 1, 0, 2]);
    }
}
