//! Safeguards on a Newton step shared by both couplings: the film limiter (fraction to the
//! boundary) and the film thickness below which a node counts as closed.

/// Fraction to the boundary for the film: the largest s <= 1 such that the step
/// H - s dH keeps at least `keep` H at every node with H > 0, and the node that binds (None
/// when the full step is allowed).
pub fn film_step_limit(h: &[f64], dh: &[f64], keep: f64) -> (f64, Option<usize>) {
    let mut s: f64 = 1.0;
    let mut binding = None;
    for (k, (&hk, &dk)) in h.iter().zip(dh).enumerate() {
        if dk > 0.0 && hk > 0.0 && (1.0 - keep) * hk / dk < s {
            s = (1.0 - keep) * hk / dk;
            binding = Some(k);
        }
    }
    (s, binding)
}

/// Dimensionless film H = h R / a^2 below which a node counts as closed while Newton keeps
/// pushing it down: 1e-8 a^2/R is a fraction of a picometre on every scene here (a^2/R is
/// 10-100 um), far below a molecule, so no lubricant film is left to compute.
pub const FILM_COLLAPSE: f64 = 1e-8;

#[cfg(test)]
mod tests {
    use super::{film_step_limit, FILM_COLLAPSE};

    #[test]
    fn the_film_limiter_keeps_a_fifth_and_names_the_binding_node() {
        // Node 1 would lose twice its film: s = 0.8 * 5e-9 / 1e-8 = 0.4 leaves 1e-9 there.
        let (h, dh) = ([1e-2, 5e-9, 1.0], [1e-3, 1e-8, -1.0]);
        let (s, k) = film_step_limit(&h, &dh, 0.2);
        assert!((s - 0.4).abs() < 1e-15 && k == Some(1));
        assert!((h[1] - s * dh[1] - 0.2 * h[1]).abs() < 1e-24);
        // That node's film is below the collapse threshold: the solver would stop here.
        assert!(h[1] < FILM_COLLAPSE);
        // A step that thins no film by more than 80 % is taken whole.
        assert_eq!(film_step_limit(&h, &[1e-3, 1e-9, 0.5], 0.2), (1.0, None));
    }
}
