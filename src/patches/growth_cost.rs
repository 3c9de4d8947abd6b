//! Eq. 3: the growth cost `C(P, t) = E(P, t) · D(s_P, t)^(2β) / A_P` and the options of cone
//! patches.
//!
//! Normalisation (the paper leaves the units open): `D^(2β)/A_P` has units length^(2β−2), so
//! the paper's cost depends on the mesh scale and resolution. We use
//! `C(P, t) = E(P, t) · (D(s_P, t) / √A_P)^(2β)`, i.e. the path length measured in units of
//! the patch's own size: dimensionless, invariant under scaling, and for a round patch the
//! frontier ratio stays near `1/√π` while an elongated patch's far end grows like
//! `√(length/width)`, so the `D` factor still penalises far and elongated growth as the
//! paper intends. `D` is the shortest path from the seed triangle to `t` through the patch's
//! dual graph (face centroids joined across shared edges, Euclidean centroid distances),
//! computed by Dijkstra inside the patch (see `grow.rs`).

use serde::Serialize;

/// Options of the cone patches of Sec. 3.2 (defaults from the paper where it gives them).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConeOptions {
    /// Exponent β of the path length in Eq. 3. Default 0.7 (paper).
    pub beta: f64,
    /// Growth threshold C_max of Eq. 3: a face is added only while its cost is below it.
    /// Default 0.1 (paper).
    pub c_max: f64,
    /// Rings of processed faces added after growth (Sec. 4.2, "Expansion of cone patches"),
    /// so consecutive patches overlap. Default 2 (the paper uses 1-2; with 1 the seams keep
    /// more of the input's triangles: paper-notes.md, Algorithm 1).
    pub expand_rings: usize,
    /// Refit rounds: after growth stops, refit the cone (Eq. 2) to the whole grown patch and
    /// grow again, this many times (stopping early when a round adds nothing). The paper
    /// fits once, from the seed's 1-ring (`0`); a 1-ring often has only two distinct
    /// normals (planar quads of a cylinder or cone) and then fixes the cone poorly. Default 1.
    pub refit_rounds: usize,
    /// Upper bound on the faces added by growth (not counting expansion); `None` = no bound.
    /// Default `None` (the paper has none).
    pub max_faces: Option<usize>,
    /// Trim a ragged expansion through needle faces ([`super::expand::trim_ragged`]): on for
    /// metrics with absolute sizes (a user's metric), whose earlier patches leave needles.
    /// Default `false`.
    pub trim_ragged: bool,
}

impl Default for ConeOptions {
    fn default() -> Self {
        ConeOptions {
            beta: 0.7,
            c_max: 0.1,
            expand_rings: 2,
            refit_rounds: 1,
            max_faces: None,
            trim_ragged: false,
        }
    }
}

/// Eq. 3 with our normalisation: `E · (D / √A_P)^(2β)`. `area_p ≤ 0` gives `+∞` unless
/// `e == 0` or `d == 0` (then 0).
#[inline]
pub fn growth_cost(e: f64, d: f64, area_p: f64, beta: f64) -> f64 {
    if e == 0.0 || d == 0.0 {
        return 0.0;
    }
    if area_p.is_nan() || area_p <= 0.0 {
        return f64::INFINITY;
    }
    e * (d / area_p.sqrt()).powf(2.0 * beta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_is_scale_invariant_and_monotone() {
        let c1 = growth_cost(0.01, 0.3, 0.05, 0.7);
        // Scaling lengths by s scales D by s and A_P by s².
        let s = 7.5;
        let c2 = growth_cost(0.01, 0.3 * s, 0.05 * s * s, 0.7);
        assert!((c1 - c2).abs() < 1e-15 * c1.max(1.0));
        assert!(growth_cost(0.02, 0.3, 0.05, 0.7) > c1);
        assert!(growth_cost(0.01, 0.4, 0.05, 0.7) > c1);
        assert!(growth_cost(0.01, 0.3, 0.08, 0.7) < c1);
        assert_eq!(growth_cost(0.0, 1.0, 0.0, 0.7), 0.0);
        assert_eq!(growth_cost(0.1, 1.0, 0.0, 0.7), f64::INFINITY);
    }
}
