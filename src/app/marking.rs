//! What each level of the adaptive loop refines ([`super::adapt`]): the marking of the
//! contact triangles, and the size field of the next level built from it.
//!
//! - Goal-oriented marking (`accuracy.marking` = theta > 0): the mass-flux residual of
//!   each triangle weighted by how much it moves the target values (their adjoints), the
//!   fewest triangles carrying the fraction theta of the total (Doerfler); those far above
//!   the smallest marked indicator are quartered while the target is far ([`QUARTER_RATIO`],
//!   [`QUARTER_ESTIMATE`]).
//! - Zone marking (`accuracy.marking = 0`): every triangle of the pressurised zone.
use super::adapt::MIN_ADAPTIVE_SIZE;
use super::estimate::Estimate;
use super::Context;
use crate::case::Scene;
use crate::ehl::driver::{self, Adjoint};
use crate::ehl::post::{FieldsOnFace, FilmStats};
use crate::ehl::system::jump_terms_of;
use crate::error::Error;
use crate::friction::pass::FrictionResult;
use crate::mesh::size_field::SizeField;
use crate::mesh::spec::dyadic_size;
use crate::mesh::Mesh;
use crate::reynolds::cavitation::Cavitation;
use crate::reynolds::estimate::{dorfler_mark, element_residual};
use crate::reynolds::jump::{edge_terms, jump_coefficient, triangle_shares, EdgeJump};
use crate::reynolds::multiplier::{FaceElement, Multipliers};
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

/// A contact triangle with a nodal pressure above this (units of p_H) is in the
/// pressurised zone, which every level refines. At 1e-3 the zone reaches far into the
/// slow inlet build-up, where refining changes hc and hm by about 1e-5: 1e-2 gives
/// the same films with 40 % fewer unknowns (docs/accuracy.md, "What a level refines").
const PRESSURISED: f64 = 1e-2;

/// The outward fluxes of an edge at its two Gauss points summed over its triangles, the
/// triangles (one or two) and how many there are.
type EdgeFluxes = ([f64; 2], [usize; 2], u8);

/// A value at each of a triangle's three vertices (its corners, or the velocity there).
type Corners = [[f64; 2]; 3];

/// The indicator of every contact triangle of a converged level (on every rank: each holds
/// the whole iterate).
pub(super) fn indicators(scene: &Scene, fields: &FieldsOnFace) -> Vec<f64> {
    let mesh = fields.mesh;
    let lub = driver::lubricant(scene);
    let fluid = lub.fluid(driver::lambda_bar(scene));
    let vel = driver::velocity_field(scene);
    let cavitation = match scene.effects.cavitation {
        crate::case::CavitationModel::Penalty => Cavitation::Penalty(scene.reynolds.penalty),
        crate::case::CavitationModel::Complementarity => Cavitation::Complementarity,
        crate::case::CavitationModel::Off => Cavitation::Off,
    };
    let n = mesh.contact_tris.len();
    let nodal = |k: usize| (mesh.contact_tris[k].map(|n| fields.p_node(n)), mesh.contact_tris[k].map(|n| fields.h_node(n)));
    let verts_vel: Vec<(Corners, Corners)> = (0..n)
        .map(|k| {
            let verts = mesh.contact_tri_xz(k);
            (verts, verts.map(|x| vel(x[0], x[1])))
        })
        .collect();
    // Under complementarity the interior residual is the stabilised element's: less the
    // cavitation multiplier, measured as the Newton residual measures it.
    let multipliers = (cavitation == Cavitation::Complementarity).then(|| {
        let areas: Vec<f64> = verts_vel.iter().map(|(v, _)| crate::fem::p2tri::tri_area(v)).collect();
        let mut m = Multipliers::new(&mesh.contact_tris, &areas);
        // The multiplier is measured with the Galerkin part alone (no penalty under
        // complementarity).
        m.evaluate(
            n,
            |k| {
                let (p, h) = nodal(k);
                FaceElement { nodes: &mesh.contact_tris[k], verts: &verts_vel[k].0, vel: &verts_vel[k].1, p, h }
            },
            &fluid,
            &driver::stabilisation(scene, 0.0),
        );
        m
    });
    let mut eta = vec![0.0; n];
    // Edge (low, high vertex id) -> outward fluxes at its Gauss points, ordered from the
    // low to the high vertex, summed over the two triangles that share it.
    // Ordered: every rank adds the jumps in the same order, so the indicators, and the
    // marking every rank meshes from, agree to the last bit.
    let mut jumps: BTreeMap<(u32, u32), EdgeFluxes> = BTreeMap::new();
    for (k, tri) in mesh.contact_tris.iter().enumerate() {
        let (p, h) = nodal(k);
        let g = multipliers.as_ref().map(|m| m.of(tri));
        let r = element_residual(&verts_vel[k].0, &p, &h, &verts_vel[k].1, &fluid, cavitation, g.as_ref());
        eta[k] = r.interior;
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            let f = if a < b { r.edge_flux[e] } else { [r.edge_flux[e][1], r.edge_flux[e][0]] };
            let entry = jumps.entry((a.min(b), a.max(b))).or_insert(([0.0; 2], [k, k], 0));
            entry.0[0] += f[0];
            entry.0[1] += f[1];
            entry.1[entry.2 as usize % 2] = k;
            entry.2 += 1;
        }
    }
    for (sum, owners, count) in jumps.values() {
        // Boundary edges (one owner) carry the Dirichlet condition: no jump.
        if *count == 2 {
            let j = sum[0].abs() + sum[1].abs();
            eta[owners[0]] += 0.5 * j;
            eta[owners[1]] += 0.5 * j;
        }
    }
    eta
}

/// Length of the longest edge of every contact triangle (units of a).
pub(super) fn longest_edges(mesh: &Mesh) -> Vec<f64> {
    (0..mesh.contact_tris.len())
        .map(|k| {
            let p = mesh.contact_tri_xz(k);
            (0..3).map(|e| (p[e][0] - p[(e + 1) % 3][0]).hypot(p[e][1] - p[(e + 1) % 3][1])).fold(0.0, f64::max)
        })
        .collect()
}

/// The size field of the next level: marked triangles at half their size, the others at
/// theirs (a triangle of a Kuhn cell of size h has its longest edge h sqrt 2, or h one
/// bisection further; both halve to h/2 and keep h). `edges`: [`longest_edges`].
pub(super) fn next_field(mesh: &Mesh, edges: &[f64], marked: &[bool], growth: f64) -> SizeField {
    field_of_sizes(mesh, &halved(edges, marked), growth)
}

/// Each triangle's size with the `marked` ones halved (`edges`: [`longest_edges`]).
fn halved(edges: &[f64], marked: &[bool]) -> Vec<f64> {
    edges.iter().zip(marked).map(|(&e, &m)| if m { 0.5 * e } else { e }).collect()
}

/// The size field with every contact triangle at the dyadic size of `sizes[t]` (units of a,
/// not below [`MIN_ADAPTIVE_SIZE`]).
pub(super) fn field_of_sizes(mesh: &Mesh, sizes: &[f64], growth: f64) -> SizeField {
    let sizes: Vec<f64> = sizes.iter().map(|&e| dyadic_size(e).max(MIN_ADAPTIVE_SIZE)).collect();
    let smallest = sizes.iter().cloned().fold(f64::INFINITY, f64::min);
    let mut f = SizeField::new(mesh.spec.contact, 0.5 * smallest, growth, mesh.spec.contact_size);
    for (k, &size) in sizes.iter().enumerate() {
        f.impose_triangle(&mesh.contact_tri_xz(k), size);
    }
    f.grade();
    f
}

/// The contact triangles whose centroid lies within `radius` (units of a) of the contact
/// centre.
pub(super) fn within_radius(mesh: &Mesh, radius: f64) -> Vec<bool> {
    (0..mesh.contact_tris.len())
        .map(|t| {
            let p = mesh.contact_tri_xz(t);
            ((p[0][0] + p[1][0] + p[2][0]) / 3.0).hypot((p[0][1] + p[1][1] + p[2][1]) / 3.0) <= radius
        })
        .collect()
}

/// The contact triangles that reach into one of the annuli `bands` (radius, half width;
/// units of a): some vertex inside it, or vertices on both sides of it.
pub(super) fn within_bands(mesh: &Mesh, bands: &[(f64, f64)]) -> Vec<bool> {
    (0..mesh.contact_tris.len())
        .map(|t| {
            let r = mesh.contact_tri_xz(t).map(|p| p[0].hypot(p[1]));
            let (lo, hi) = (r.iter().cloned().fold(f64::INFINITY, f64::min), r.iter().cloned().fold(0.0, f64::max));
            bands.iter().any(|&(rc, w)| lo <= rc + w && hi >= rc - w)
        })
        .collect()
}

/// The eligible triangles: those not yet at [`MIN_ADAPTIVE_SIZE`]. `edges`: [`longest_edges`].
fn eligible(edges: &[f64]) -> Vec<bool> {
    edges.iter().map(|&e| e > 1.5 * MIN_ADAPTIVE_SIZE).collect()
}

/// Zone marking (`accuracy.marking = 0`): every triangle of the pressurised zone, where hc
/// and hm are carried (the film is transported from the inlet build-up through the Hertz
/// zone to the side lobes and the outlet), so that a change between levels measures their
/// error wherever it is made.
pub(super) fn zone_mark(fields: &FieldsOnFace, edges: &[f64]) -> Vec<bool> {
    let eligible = eligible(edges);
    fields.mesh.contact_tris.iter().enumerate().map(|(t, tri)| eligible[t] && tri.iter().any(|&n| fields.p_node(n) > PRESSURISED)).collect()
}

/// A place where the film is within this fraction of hm is a goal of the marking too
/// ([`FieldsOnFace::near_minima`]). On cases/hard/slow the goal at hm's place alone let the
/// minimum move between levels 2, 3 and 4 from the side lobe at (0.11, -0.98) a to (0.63,
/// -0.75) a and back, hm changing by -5.8 % and +7.6 %: the second place was within 6 %.
const NEAR_MINIMUM: f64 = 0.1;

/// Near-minimum places closer than this (units of a) count as one place.
const NEAR_MINIMUM_SEPARATION: f64 = 0.25;

/// At most this many places of hm are goals (each costs one transposed solve on the
/// level's LU).
const NEAR_MINIMUM_PLACES: usize = 4;

/// The interior contact edges with their gradient-jump coefficient gamma_E, as the system
/// assembles them (none when the scene's `reynolds.gradient_jump` is 0).
fn jump_edges(scene: &Scene, mesh: &Mesh) -> Vec<(usize, usize, EdgeJump, f64)> {
    let c_j = scene.reynolds.gradient_jump;
    let vel = driver::velocity_field(scene);
    jump_terms_of(mesh, c_j, |_| true)
        .into_iter()
        .map(|(a, b, edge)| {
            let gamma = jump_coefficient(c_j, edge.h_e, vel(edge.mid[0], edge.mid[1]));
            (a, b, edge, gamma)
        })
        .collect()
}

/// A value the marking serves: its name, the pressure part of its adjoint and its scale
/// (the film for hc and hm, the friction coefficient's magnitude for fx and fz).
pub(super) struct Goal {
    pub(super) name: &'static str,
    /// The adjoint's pressure part, per mesh node.
    pub(super) z: Vec<f64>,
    /// The value's scale (its own value; for fx and fz the friction coefficient's magnitude).
    pub(super) scale: f64,
}

/// The goals of a converged level, each with its adjoint from the level's LU: hc, hm at
/// each place where the film comes near it, and, with friction (`friction`: this level's
/// fx, fz), fx and fz, each relative to the friction coefficient's magnitude as in the
/// estimate (fz vanishes without spin, and on a half domain it is no goal).
pub(super) fn goals(
    ctx: &Context,
    scene: &Scene,
    adjoint: &Adjoint,
    fields: &FieldsOnFace,
    st: &FilmStats,
    friction: Option<&FrictionResult>,
) -> Result<Vec<Goal>, Error> {
    let film = |at: [f64; 2]| -> Result<Vec<f64>, Error> { Ok(adjoint.pressure_part(&adjoint.film(ctx, &film_weights(fields, at)?)?)) };
    let mut goals = vec![Goal { name: "hc", z: film([0.0, 0.0])?, scale: st.hc }];
    // hm is a minimum: every place where the film comes near it is a goal of its own, or the
    // next level refines only the present minimum and the minimum moves to a place left
    // coarse (docs/accuracy.md, "What a level refines").
    for at in fields.near_minima(st.hm, NEAR_MINIMUM, NEAR_MINIMUM_SEPARATION, NEAR_MINIMUM_PLACES) {
        goals.push(Goal { name: "hm", z: film(at)?, scale: st.hm });
    }
    if let Some(f) = friction {
        let setup = super::lubricated::friction_setup(scene, fields.mesh.spec.contact).expect("a scene with friction");
        let grad = crate::friction::pass::friction_gradient(fields, &setup, &f.rules, &super::lubricated::OverRanks(ctx))?;
        let magnitude = f.fx.hypot(f.fz);
        // On a half domain fz vanishes by symmetry, and so does its gradient.
        for (name, c) in [("fx", 0), ("fz", 1)].into_iter().take(if fields.half() { 1 } else { 2 }) {
            let dh: Vec<(u32, f64)> = grad.nodes.iter().map(|(n, g)| (*n, g[2 * c + 1])).collect();
            let dp: Vec<(u32, f64)> = grad.nodes.iter().map(|(n, g)| (*n, g[2 * c])).collect();
            goals.push(Goal { name, z: adjoint.pressure_part(&adjoint.functional(ctx, &dh, &dp)?), scale: magnitude });
        }
    }
    // Under complementarity a cavitated row of the Jacobian is a unit row (P = 0), and the
    // adjoint there is the goal's sensitivity to that constraint, not a weight of a flux
    // error: as for any obstacle problem the residual counts on the pressurised set only.
    // Left in, it weighted the free boundary's triangles and level 0 of table2-ue2 marked
    // 113 of 720 triangles where the penalty marks 29 (docs/numerics.md).
    if scene.effects.cavitation == crate::case::CavitationModel::Complementarity {
        use crate::reynolds::dual::Dual;
        for g in &mut goals {
            for &n in &fields.mesh.contact_nodes {
                g.z[n as usize] *= crate::reynolds::cavitation::pressurised(Dual::<1>::constant(fields.p_node(n))).v;
            }
        }
    }
    Ok(goals)
}

/// Goal-oriented marking: each triangle's mass-flux indicator weighted by how much a flux
/// error there moves each goal's value (its adjoint's hierarchical P2 surplus over the
/// triangle's edges: the part of the adjoint the triangle's P1 interpolant misses),
/// relative to that value, summed over the goals ([`goals`]), plus the gradient-jump
/// term's share of each value's error ([`triangle_shares`]); Doerfler marking at `theta`.
pub(super) fn goal_mark(
    ctx: &Context,
    scene: &Scene,
    fields: &FieldsOnFace,
    goals: &[Goal],
    edges: &[f64],
    theta: f64,
    quarter: bool,
) -> Marking {
    let t0 = Instant::now();
    let mesh = fields.mesh;
    let rho = indicators(scene, fields);
    let surplus = |z: &[f64], tri: &[u32; 6]| {
        (0..3).map(|e| (z[tri[3 + e] as usize] - 0.5 * (z[tri[e] as usize] + z[tri[(e + 1) % 3] as usize])).abs()).fold(0.0, f64::max)
    };
    // The gradient-jump term's share of each value's error (none without the term).
    let jumps = jump_edges(scene, mesh);
    let p: Vec<f64> = (0..mesh.nodes.len()).map(|n| fields.p_node(n as u32)).collect();
    let n = mesh.contact_tris.len();
    let (mut eta, mut from_jumps) = (vec![0.0; n], 0.0);
    // The term's first-order effect on each value, relative to it (%).
    let mut effects = Vec::with_capacity(goals.len());
    // Each goal's part of the summed indicator, by name (the hm places are consecutive
    // goals: one part), for the log.
    let mut parts: Vec<(&str, f64)> = Vec::new();
    for Goal { name, z, scale: v } in goals {
        let terms = edge_terms(&jumps, &p, z);
        effects.push(100.0 * terms.iter().sum::<f64>() / v);
        let shares = triangle_shares(&jumps, n, &terms);
        let mut sum = 0.0;
        for (t, tri) in mesh.contact_tris.iter().enumerate() {
            let e = (rho[t] * surplus(z, tri) + shares[t]) / v.abs();
            eta[t] += e;
            sum += e;
            from_jumps += shares[t] / v.abs();
        }
        match parts.last_mut() {
            Some((last, s)) if last == name => *s += sum,
            _ => parts.push((name, sum)),
        }
    }
    if !jumps.is_empty() {
        // What the term does to hc and hm (at hm's place), through their adjoints. Logged,
        // not part of the estimate (docs/accuracy.md, "A change small by chance after level 0").
        ctx.log(format!(
            "accuracy: without the gradient-jump term hc would move by {:+.2} % and hm by {:+.2} % (first order, from their adjoints)",
            effects[0], effects[1]
        ));
    }
    let marking = Marking::of(&eta, &eligible(edges), theta, quarter);
    let total: f64 = parts.iter().map(|(_, s)| s).sum();
    let places = goals.iter().filter(|g| g.name == "hm").count();
    ctx.log(format!(
        "accuracy: goal-oriented marking (the weighted indicator: {}{}): {} of {} contact triangles marked ({} of them quartered{}; fraction {theta} of the weighted indicator{}), {:.1} s",
        parts.iter().map(|(name, s)| format!("{name} {:.0} %", 100.0 * s / total)).collect::<Vec<_>>().join(", "),
        if places > 1 { format!("; hm at {places} places") } else { String::new() },
        marking.marked.iter().filter(|&&m| m).count(),
        marking.marked.len(),
        marking.quartered(),
        // The quartered triangles' share of the marked indicator, which says how much of
        // the level the crossing guard's two halvings stand for (docs/accuracy.md, Open).
        match marking.quartered() {
            0 => String::new(),
            q => format!(", {:.0} % of the marked indicator", 100.0 * marking.indicator_share(q)),
        },
        if jumps.is_empty() {
            String::new()
        } else {
            format!("; {:.1} % of it from the gradient-jump term", 100.0 * from_jumps / eta.iter().sum::<f64>())
        },
        t0.elapsed().as_secs_f64()
    ));
    marking
}

/// A marked triangle whose indicator is at least this many times the smallest marked one is
/// quartered instead of halved. A halved triangle's four children each keep at least 1/16
/// of its indicator where the fields are no better than Lipschitz (the slowest an indicator
/// of P2 fields falls: 1/4 from the area, 1/2 from the residual's density, 1/2 from the
/// adjoint's surplus), so its children would still be marked at the next level; quartering
/// now saves that level. On table2-ue2 at target 0.02 the 0.0625 a level quarters 10 of its
/// 115 marked triangles, the notch of the side lobe where hm sits, and the next level's hm
/// error falls from -0.73 % to +0.35 % for 9 % more unknowns (docs/accuracy.md,
/// "Quartering where halving is not enough").
pub const QUARTER_RATIO: f64 = 16.0;

/// A level quarters only when one of its estimated errors exceeds this many times the
/// target: quartering saves a level only when more than one level of halving is still
/// ahead, and one halving takes an error down by about 4 (second order, as hc and hm
/// converge on the adaptive levels). Without the guard, M = 20, L = 10 at target 0.01
/// quartered its 0.0625 a level, whose estimates (0.89 %, 0.17 %) were already below the
/// target, into a 0.0156 a level that needs the raised gradient-jump factor: 229 s against
/// 28 s for the same films. Level 0 has no estimate and halves.
pub const QUARTER_ESTIMATE: f64 = 4.0;

/// Whether a level's marking quarters ([`QUARTER_RATIO`]), from the level's estimate
/// `est` (None on the first level), the `target`, whether fz is a target (`fz_target`:
/// friction on a full domain) and whether Newton reached the level only through a
/// continuation (`continued`). Quartering pays only with more than one level of halving
/// still ahead ([`QUARTER_ESTIMATE`]); not while fz is a target, whose error is spread and
/// falls at first order (cases/hard/spin-0.5deg stopped short of 0.01 with it); and not
/// after a continuation: a quartered level starts from a pressure interpolated across two
/// halvings, and where one halving already needed a continuation, the quartered level cost
/// far more than it saved on six of the nine Moes points where it happened (M = 500,
/// L = 20: 712 s against 132 s halving; M = 1000, L = 15: 804 s against 308 s; it paid on
/// three, M = 1000, L = 5: 218 s against 453 s; 2,989 s against 2,278 s over the nine;
/// docs/accuracy.md, "Quartering where halving is not enough").
pub(super) fn quarters(est: Option<&Estimate>, target: f64, fz_target: bool, continued: bool) -> bool {
    target >= QUARTER_FROM_TARGET
        && !fz_target
        && !continued
        && est.is_some_and(|e| e.values().iter().any(|&v| v > QUARTER_ESTIMATE * target))
}

/// The smallest target at which a level quarters. Below it the unknowns budget of 2 ranks
/// ends a run, and the change-based estimate needs a regular level sequence to certify
/// the last level inside it: with quartering, table2-ue2 at 0.001 and cases/hard/heavy-2gpa
/// at 0.0025 ended at the budget (hc's changes over quartered levels did not shrink;
/// estimates 0.24 % and 0.84 % for errors of 0.04 % and 0.02 %), where halving reached both.
/// At 0.005 and above quartering was measured to pay (table2-ue2 at 0.005 and 0.01, the
/// Moes map and the hard scenes at 0.01; docs/accuracy.md, "Quartering where halving is
/// not enough").
pub const QUARTER_FROM_TARGET: f64 = 0.005;

/// The triangles a level marks for the next one, and, when the marking ranks them
/// (goal-oriented), the marked ones by decreasing indicator with their indicator: the next
/// level can then be cut to its budget ([`cut_count`]), and the marked triangles of
/// largest indicator are quartered ([`QUARTER_RATIO`]).
pub(super) struct Marking {
    pub marked: Vec<bool>,
    pub ranked: Option<Vec<(usize, f64)>>,
    /// Whether the triangles of largest indicator are quartered ([`QUARTER_ESTIMATE`]).
    pub quarter: bool,
    /// The eligible triangles the marking left out, by decreasing indicator: what a
    /// widened marking takes next ([`Marking::widen`]).
    rest: Vec<(usize, f64)>,
    /// The smallest indicator of Doerfler's set, against which triangles are quartered
    /// (also once the marking is widened).
    smallest: f64,
}

impl Marking {
    /// A marking with no ranking (zone marking).
    pub fn unranked(marked: Vec<bool>) -> Marking {
        Marking { marked, ranked: None, quarter: false, rest: Vec::new(), smallest: 0.0 }
    }

    /// Doerfler's marking of the `eligible` triangles at the fraction `theta` of their
    /// indicators `eta`, ranked, quartering when `quarter`.
    pub fn of(eta: &[f64], eligible: &[bool], theta: f64, quarter: bool) -> Marking {
        let marked = dorfler_mark(eta, eligible, theta);
        let by_indicator = |keep: &dyn Fn(usize) -> bool| {
            let mut r: Vec<(usize, f64)> = (0..eta.len()).filter(|&t| keep(t)).map(|t| (t, eta[t])).collect();
            r.sort_by(|a, b| b.1.total_cmp(&a.1));
            r
        };
        let ranked = by_indicator(&|t| marked[t]);
        let rest = by_indicator(&|t| eligible[t] && !marked[t]);
        let smallest = ranked.last().map_or(0.0, |v| v.1);
        Marking { marked, ranked: Some(ranked), quarter, rest, smallest }
    }

    /// How many triangles the marking refines.
    pub fn count(&self) -> usize {
        self.marked.iter().filter(|&&m| m).count()
    }

    /// Whether [`Marking::widen`] has triangles left to take.
    pub fn widens(&self) -> bool {
        self.ranked.is_some() && !self.rest.is_empty()
    }

    /// Widens the marking to its `count` triangles of largest indicator (at most every
    /// eligible one; never fewer than it marks): the triangles it takes are halved, since
    /// quartering stays measured against Doerfler's set.
    pub fn widen(&mut self, count: usize) {
        let Some(r) = self.ranked.as_mut() else { return };
        let take = count.saturating_sub(r.len()).min(self.rest.len());
        for (t, eta) in self.rest.drain(..take) {
            self.marked[t] = true;
            r.push((t, eta));
        }
    }

    /// The indicator from which a marked triangle is quartered ([`QUARTER_RATIO`] times the
    /// smallest of Doerfler's set), when the marking quarters.
    fn quarter_from(&self) -> Option<f64> {
        self.ranked.as_ref().filter(|_| self.quarter)?;
        Some(QUARTER_RATIO * self.smallest)
    }

    /// The marked triangles the next level quarters (their count).
    pub fn quartered(&self) -> usize {
        match (&self.ranked, self.quarter_from()) {
            (Some(r), Some(from)) => r.iter().filter(|v| v.1 >= from).count(),
            _ => 0,
        }
    }

    /// How many halvings the next level's finest refinement makes ([`super::adapt::Level`]'s
    /// `halvings`): 2 when it quarters triangles, else 1. A cut keeps the largest, so it
    /// quarters whenever the whole marking does.
    pub fn halvings(&self) -> u32 {
        if self.quartered() > 0 {
            2
        } else {
            1
        }
    }

    /// Each contact triangle's size at the next level (units of a; `edges`:
    /// [`longest_edges`]) when the `count` marked triangles of largest indicator are refined
    /// (all of them with `None` or without a ranking): marked triangles at half their size,
    /// or a quarter when the marking quarters ([`QUARTER_RATIO`], against the whole
    /// marking's smallest indicator), the others at theirs.
    pub fn sizes(&self, edges: &[f64], count: Option<usize>) -> Vec<f64> {
        let Some(r) = &self.ranked else { return halved(edges, &self.marked) };
        let from = self.quarter_from().unwrap_or(f64::INFINITY);
        let mut sizes = edges.to_vec();
        for &(t, eta) in r.iter().take(count.unwrap_or(r.len())) {
            sizes[t] *= if eta >= from { 0.25 } else { 0.5 };
        }
        sizes
    }

    /// The share of the marked triangles' indicator that the `count` largest carry (1
    /// without a ranking).
    pub fn indicator_share(&self, count: usize) -> f64 {
        let Some(r) = &self.ranked else { return 1.0 };
        let total: f64 = r.iter().map(|v| v.1).sum();
        if total > 0.0 {
            r.iter().take(count).map(|v| v.1).sum::<f64>() / total
        } else {
            1.0
        }
    }
}

/// The next level's mesh: its size field and the halvings its finest refinement makes
/// ([`super::adapt::Level`]'s `halvings`, for the estimate's crossing guard), kept in one
/// value so that every way of making the field says how far it refines.
#[derive(Clone)]
pub(super) struct NextMesh {
    pub field: Arc<SizeField>,
    pub halvings: u32,
}

impl NextMesh {
    /// A field that refines by one halving at most (zone marking, a retried first level).
    pub fn halving(field: Arc<SizeField>) -> NextMesh {
        NextMesh { field, halvings: 1 }
    }

    /// The field of `marking` on `mesh` (`edges`: [`longest_edges`]) when its `count`
    /// triangles of largest indicator are refined (all with `None`): [`Marking::sizes`].
    pub fn marked(mesh: &Mesh, edges: &[f64], marking: &Marking, count: Option<usize>, growth: f64) -> NextMesh {
        NextMesh { field: Arc::new(field_of_sizes(mesh, &marking.sizes(edges, count), growth)), halvings: marking.halvings() }
    }
}

/// The size a level cut to the budget aims at, as a fraction of `accuracy.max_unknowns`.
pub const BUDGET_FILL: f64 = 0.9;

/// A level cut to the budget is not solved when the triangles that fit carry less than this
/// share of the marked triangles' indicator: it would cost a level's solve for a change too
/// small to bring an estimate down.
pub const MIN_BUDGET_SHARE: f64 = 0.25;

/// How a level's wall time grows with its unknowns, t ~ N^p, between consecutive levels
/// solved from the level before (monolithic, goal-oriented): p was 1.07 and 1.09 on
/// spin-0.5deg (124k -> 212k -> 464k unknowns) and 1.35, 1.18 and 1.21 on table2-ue2
/// (60k -> 95k -> 186k -> 489k); the prediction of 1.2 was within 9 % of every level's
/// time from level 3 on. It does not see Newton's path: a level that needs more iterations
/// or a continuation than the one before runs over it (spin-0.33deg's cut level: 305 s
/// against 217 s; M = 1000, L = 20's level 4: 365 s against 147 s), and the deadline then
/// stops it as before.
pub const LEVEL_TIME_EXPONENT: f64 = 1.2;

/// The time budget as it bears on the next level: the seconds left, and the level before
/// (`before` unknowns, solved in `seconds` with its adjoint and marking) whose cost per
/// unknown the prediction takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeLeft {
    pub left: f64,
    pub before: u64,
    pub seconds: f64,
}

impl TimeLeft {
    /// The wall time a level of `n` unknowns is expected to take (s).
    pub fn predicted(&self, n: u64) -> f64 {
        grown(self.seconds, self.before, n, LEVEL_TIME_EXPONENT)
    }

    /// The most unknowns a level may have and be expected to end within the time left.
    pub fn unknowns(&self) -> u64 {
        unknowns_within(self.before, self.seconds, self.left, LEVEL_TIME_EXPONENT)
    }
}

/// A level's cost (its time, its memory) at `n` unknowns, from the `cost` of a level of
/// `before` unknowns, growing like the unknowns to the power `exponent`.
pub(super) fn grown(cost: f64, before: u64, n: u64, exponent: f64) -> f64 {
    cost * (n as f64 / before.max(1) as f64).powf(exponent)
}

/// The most unknowns a level may have for its cost ([`grown`] from `cost` at `before`
/// unknowns) to stay within `limit`: none without a limit left, any number where the level
/// before cost nothing.
pub(super) fn unknowns_within(before: u64, cost: f64, limit: f64, exponent: f64) -> u64 {
    if limit <= 0.0 {
        return 0;
    }
    if !(cost > 0.0) {
        return u64::MAX;
    }
    (before as f64 * (limit / cost).powf(1.0 / exponent)).min(u64::MAX as f64) as u64
}

/// How many of the marked triangles (those of largest indicator) a level cut to `budget`
/// refines, from the meshes tried so far that were over it (`over`: count refined and
/// unknowns, the whole marking first): [`count_for`] at [`BUDGET_FILL`] of the budget,
/// always below the last count tried.
pub fn cut_count(before: u64, over: &[(usize, u64)], budget: u64) -> usize {
    let Some(&(c2, _)) = over.last() else { return 0 };
    let c = count_for(before, over, BUDGET_FILL * budget as f64).unwrap_or(0.0);
    (c as usize).min(c2.saturating_sub(1))
}

/// How many triangles (those of largest indicator) a level's marking refines for the
/// level to have `aim` of a size (unknowns or contact triangles) that was `before` on the
/// level marked, from the meshes tried (`tried`: count refined and size). The size a level
/// adds grows like a power of the count, c^p with p at most 1: the largest indicators sit
/// on the smallest elements, whose grading on the face and in the solid reaches far, and
/// the triangles after them share that grading (spin-0.33deg: p = 0.3-0.5). From one mesh
/// the count is taken in proportion (p = 1); from two, p is measured between the last two
/// and the power law extrapolated. None when the last mesh added nothing or the aim is no
/// more than `before`.
pub fn count_for(before: u64, tried: &[(usize, u64)], aim: f64) -> Option<f64> {
    let &(c2, n2) = tried.last()?;
    let room = aim - before as f64;
    let added = |n: u64| n.saturating_sub(before) as f64;
    let p = match tried.len() {
        0 | 1 => 1.0,
        k => {
            let (c1, n1) = tried[k - 2];
            let p = (added(n1) / added(n2)).ln() / (c1 as f64 / c2 as f64).ln();
            if p.is_finite() {
                p.clamp(0.1, 1.0)
            } else {
                1.0
            }
        }
    };
    (added(n2) > 0.0 && room > 0.0).then(|| c2 as f64 * (room / added(n2)).powf(1.0 / p))
}

/// How many triangles a marking widened for the next level to have `aim` contact
/// triangles refines, from the meshes tried (`tried`: count refined and contact
/// triangles; `before`: the level marked): [`count_for`], always above the last count
/// tried (twice it when the last mesh added nothing) and at most [`WIDENING_STEP`] times
/// it.
pub fn widened_count(before: u64, tried: &[(usize, u64)], aim: f64) -> usize {
    let Some(&(c2, _)) = tried.last() else { return 0 };
    count_for(before, tried, aim).map_or(2 * c2, |c| c.ceil() as usize).clamp(c2 + 1, WIDENING_STEP * c2)
}

/// A widened marking takes at most this many times the triangles of the mesh tried before:
/// the triangles after Doerfler's few share their grading, so the first added ones add
/// few contact triangles, and a power law measured on them (p near its floor of 0.1)
/// extrapolates far past the aim (M = 100, L = 20: from 19 triangles to 262, a level of
/// 2.4 times its predecessor's contact triangles where 1.65 was aimed at).
pub const WIDENING_STEP: usize = 4;

/// The P2 interpolation weights of the film at `p` (units of a) on the contact face.
pub(super) fn film_weights(fields: &FieldsOnFace, p: [f64; 2]) -> Result<Vec<(u32, f64)>, Error> {
    fields.weights_at(p[0], p[1]).ok_or_else(|| Error::numerical(format!("accuracy: ({}, {}) is not on the contact face", p[0], p[1])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::spec::MeshSpec;

    #[test]
    fn the_time_left_bounds_the_next_level_by_the_cost_of_the_one_before() {
        // spin-0.5deg, 2 ranks: level 3 had 212,548 unknowns and took 75.5 s; level 4, with
        // 463,828, took 176.9 s.
        let t = TimeLeft { left: 300.0, before: 212_548, seconds: 75.5 };
        let p = t.predicted(463_828);
        assert!((p / 176.9 - 1.0).abs() < 0.1, "predicted {p} s");
        // What fits is what the prediction says ends in the time left, and no more.
        let n = t.unknowns();
        assert!(t.predicted(n) <= 300.0 && t.predicted(n + 10) > 300.0, "{n} unknowns take {} s", t.predicted(n));
        // Less time than the level before took: fewer unknowns than it had.
        assert!(TimeLeft { left: 50.0, ..t }.unknowns() < 212_548);
        assert_eq!(TimeLeft { left: -1.0, ..t }.unknowns(), 0);
    }

    #[test]
    fn a_band_around_a_radius_is_refined_twice_and_nothing_else_moves() {
        // The default half-domain face at 0.25 a; an annulus of half width 0.1 a around
        // r = 0.95 a quartered, as a first level retried after its film closed there.
        let mut spec = MeshSpec::paper_default();
        spec.half_z = true;
        spec.contact = crate::mesh::spec::Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 0.0 };
        let mesh = crate::mesh::generate(&spec).unwrap();
        let edges = longest_edges(&mesh);
        let band = within_bands(&mesh, &[(0.95, 0.1)]);
        let centroid_r = |m: &Mesh, t: usize| {
            let p = m.contact_tri_xz(t);
            ((p[0][0] + p[1][0] + p[2][0]) / 3.0).hypot((p[0][1] + p[1][1] + p[2][1]) / 3.0)
        };
        // Every triangle whose centroid is in the annulus is marked; none beyond one
        // element (0.25 sqrt 2) of it.
        for (t, &marked) in band.iter().enumerate() {
            let r = centroid_r(&mesh, t);
            if (r - 0.95).abs() <= 0.1 {
                assert!(marked, "triangle {t} at r = {r} not marked");
            }
            if (r - 0.95).abs() > 0.1 + 0.36 {
                assert!(!marked, "triangle {t} at r = {r} marked");
            }
        }
        let sizes: Vec<f64> = band.iter().zip(&edges).map(|(&b, &e)| if b { 0.25 * e } else { e }).collect();
        spec.size_field = Some(std::sync::Arc::new(field_of_sizes(&mesh, &sizes, 1.0)));
        let finer = crate::mesh::generate(&spec).unwrap();
        let fine_edges = longest_edges(&finer);
        for (t, &edge) in fine_edges.iter().enumerate() {
            let r = centroid_r(&finer, t);
            // In the annulus: a quarter of 0.25 a (longest edge h or h sqrt 2).
            if (r - 0.95).abs() <= 0.1 {
                assert!(edge <= 0.0625 * 2f64.sqrt() * 1.001, "r = {r}: edge {edge}");
            }
            // Far from it (beyond the grading): the face as it was.
            if (r - 0.95).abs() > 1.0 && r < 2.5 {
                assert!(edge >= 0.25 * 0.999, "r = {r}: edge {edge}");
            }
        }
        assert!(finer.contact_tris.len() > mesh.contact_tris.len());
    }

    #[test]
    fn a_level_over_the_budget_is_cut_to_the_count_of_its_marking_that_fits() {
        // 400k before, 800k with all 1000 marked triangles: 140k of room below 90 % of a
        // 600k budget for 400k added, so 350 of them.
        assert_eq!(cut_count(400_000, &[(1000, 800_000)], 600_000), 350);
        // 350 gave 620k: the added unknowns go like c^p, p = ln(400/220)/ln(1000/350) =
        // 0.569, so 350 (140/220)^(1/p).
        let p = (400.0f64 / 220.0).ln() / (1000.0f64 / 350.0).ln();
        let want = (350.0 * (140.0f64 / 220.0).powf(1.0 / p)) as usize;
        assert_eq!(cut_count(400_000, &[(1000, 800_000), (350, 620_000)], 600_000), want);
        assert!(want < 222, "{want}: below the proportional count");
        // On spin-0.33deg's meshes (level 3: 392,809 unknowns) the power law from the first
        // two meshes lands within 3 % of the budget's aim where the proportional count took
        // three more meshes: 3181 triangles gave 1,014,384 unknowns, 753 gave 700,853, 146
        // gave 607,508 (measured).
        let c = cut_count(392_809, &[(3181, 1_014_384), (753, 700_853)], 600_000);
        assert!((140..190).contains(&c), "{c}");
        // No room: none.
        assert_eq!(cut_count(560_000, &[(1000, 1_000_000)], 600_000), 0);
        assert_eq!(cut_count(400_000, &[], 600_000), 0);
        // The largest of the ranked: the first of the ranking, whatever their index, and
        // the share of the indicator they carry.
        let m = Marking::of(&[3.0, 1.0, 2.0, 5.0], &[true; 4], 0.9, true);
        assert_eq!(m.ranked, Some(vec![(3, 5.0), (0, 3.0), (2, 2.0)]));
        assert_eq!(m.sizes(&[1.0; 4], Some(2)), vec![0.5, 1.0, 1.0, 0.5]);
        assert!((m.indicator_share(2) - 0.8).abs() < 1e-12);
        assert_eq!(Marking::unranked(vec![true, false]).sizes(&[1.0, 1.0], Some(0)), vec![0.5, 1.0]);
    }

    #[test]
    fn a_widened_marking_takes_the_next_triangles_by_indicator_and_halves_them() {
        // Doerfler at 0.5 takes 40 of 40, 8, 4, 2, 1 (and 0.5 not eligible); quartering from
        // 16 times it, so nothing is quartered even once triangles of smaller indicator join.
        let mut m = Marking::of(&[4.0, 40.0, 2.0, 8.0, 0.5, 1.0], &[true, true, true, true, false, true], 0.5, true);
        assert_eq!(m.count(), 1);
        m.widen(3);
        assert_eq!(m.marked, vec![true, true, false, true, false, false]);
        assert_eq!(m.quartered(), 0);
        assert_eq!(m.sizes(&[1.0; 6], None), vec![0.5, 0.5, 1.0, 0.5, 1.0, 1.0]);
        // Never narrowed, and never beyond the eligible triangles.
        m.widen(2);
        assert_eq!(m.count(), 3);
        m.widen(10);
        assert_eq!(m.count(), 5);
        assert!(!m.widens());
        assert!(!Marking::unranked(vec![true, false]).widens());
    }

    #[test]
    fn a_widened_count_aims_at_the_growth_from_the_meshes_tried() {
        // M = 100, L = 20's level 1: 965 contact triangles, 7 marked gave 1,201. For 1,592
        // (1.65 times), in proportion: 7 * 627 / 236, rounded up.
        assert_eq!(widened_count(965, &[(7, 1201)], 1592.0), 19);
        // 19 gave 1,400: p = ln(236/435)/ln(7/19) = 0.61, so 19 (627/435)^(1/p).
        let p = (236.0f64 / 435.0).ln() / (7.0f64 / 19.0).ln();
        let want = (19.0 * (627.0f64 / 435.0).powf(1.0 / p)).ceil() as usize;
        assert_eq!(widened_count(965, &[(7, 1201), (19, 1400)], 1592.0), want);
        // A mesh that grew little from the count before: at most 4 times the count.
        assert_eq!(widened_count(965, &[(7, 1201), (19, 1215)], 1592.0), 76);
        // Always more than the last count; twice it when the last mesh added nothing.
        assert_eq!(widened_count(965, &[(7, 1700)], 1592.0), 8);
        assert_eq!(widened_count(965, &[(7, 965)], 1592.0), 14);
    }

    #[test]
    fn a_marked_triangle_far_above_the_smallest_marked_indicator_is_quartered() {
        // Indicators 40, 32, 3, 2: 32 is 16 times the smallest marked one, 3 is not.
        let mut m = Marking::of(&[32.0, 40.0, 2.0, 3.0], &[true; 4], 1.0, true);
        assert_eq!(m.quartered(), 2);
        assert_eq!(m.sizes(&[0.25; 4], None), vec![0.0625, 0.0625, 0.125, 0.125]);
        // Cut to the largest one: the others keep their size; the threshold stays the whole
        // marking's, so a cut level quarters what the full one would.
        assert_eq!(m.sizes(&[0.25; 4], Some(1)), vec![0.25, 0.0625, 0.25, 0.25]);
        // A level whose estimates are near the target halves every marked triangle.
        m.quarter = false;
        assert_eq!(m.quartered(), 0);
        assert_eq!(m.sizes(&[0.25; 4], None), vec![0.125; 4]);
        // Zone marking has no ranking: every marked triangle is halved.
        assert_eq!(Marking::unranked(vec![true, false]).quartered(), 0);
    }

    #[test]
    fn a_level_quarters_only_far_from_the_target_after_plain_newton_and_without_fz() {
        // table2-ue2's level 2 at target 0.01: estimates 16 % and 43 %, plain Newton.
        let far = Estimate { hc: 0.16, hm: 0.43, friction: None, penalty: None, friction_penalty: None, models_gap: None };
        assert!(quarters(Some(&far), 0.01, false, false));
        // Its level 3 at 0.18 % and 0.47 %: within 4 times the target, one halving ahead.
        let near = Estimate { hc: 0.0018, hm: 0.0047, friction: None, penalty: None, friction_penalty: None, models_gap: None };
        assert!(!quarters(Some(&near), 0.01, false, false));
        // ... and more than one at target 0.002, where the budget of 2 ranks binds: halving.
        assert!(!quarters(Some(&near), 0.002, false, false));
        assert!(quarters(Some(&far), 0.005, false, false));
        // Level 0 has no estimate; a level reached through a continuation, or with fz
        // among the targets, halves.
        assert!(!quarters(None, 0.01, false, false));
        assert!(!quarters(Some(&far), 0.01, false, true));
        let spin = Estimate { hc: 0.05, hm: 0.05, friction: Some([0.01, 0.2]), penalty: None, friction_penalty: None, models_gap: None };
        assert!(!quarters(Some(&spin), 0.01, true, false));
        // One estimate far off is enough (fx among them).
        let fx = Estimate { hc: 0.001, hm: 0.001, friction: Some([0.05, 0.0]), penalty: None, friction_penalty: None, models_gap: None };
        assert!(quarters(Some(&fx), 0.01, false, false));
    }
}
