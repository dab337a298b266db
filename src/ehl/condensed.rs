//! The EHL system with the elastic block condensed onto the contact face
//! (see [`crate::solid::condense`]): unknowns P at the Reynolds nodes and H0 only,
//!   Reynolds:      R(P, H(P, H0)) + penalty(P) = 0,   H = H0 + (X^2 + Z^2)/2 - C P
//!   load balance:  integral of P - W = 0,
//! with U_y = C P the face deflection. It has the same solution as the monolithic system of
//! [`super::system`] (exact elimination of U). The Jacobian is dense in P (every pressure
//! deflects every face node): dR/dP - dR/dH C, filled block by block into a dense matrix
//! (options prefix `condensed_`; ScaLAPACK's LU on 2+ ranks, LAPACK's on one; for rigid
//! solids a sparse AIJ matrix); its size is set by the Reynolds mesh alone, not by the 3D
//! mesh.
use super::step::{film_step_limit, FILM_COLLAPSE};
use super::system::EhlProblem;
use super::system::{clip_pressure_step, complementarity, penalty_law, pressure_step_floor, EhlParams, Lubricant, CAVITATION_SMOOTHING};
use crate::fem::p2tri::{p2_tri_weights, tri_area};
use crate::mesh::Mesh;
use crate::petsc::snes::{Eval, Problem};
use crate::petsc::{Matrix, Result, Vector};
use crate::reynolds::element::{reynolds_element, reynolds_element_with_multiplier, ElementOut, Fluid};
use crate::reynolds::jump::JumpRows;
use crate::reynolds::multiplier::{FaceElement, Multipliers};
use crate::solid::condense::Compliance;

/// Numbering of the condensed unknowns: P in `comp.cols` order, then H0; rank r owns
/// `ranges[r]..ranges[r + 1]` (H0, the last row, is on the last rank with rows).
#[derive(Debug, Clone)]
pub struct CondensedLayout {
    pub n_p: usize,
    pub ranges: Vec<usize>,
    /// Per mesh node: its pressure unknown or -1.
    pub p_index: Vec<i32>,
    /// Per mesh node: its row in the compliance (face index) or -1.
    pub face_index: Vec<i32>,
}

impl CondensedLayout {
    pub fn new(mesh: &Mesh, comp: &Compliance, nranks: usize) -> Self {
        let n_p = comp.cols.len();
        let mut p_index = vec![-1i32; mesh.nodes.len()];
        for (j, &n) in comp.cols.iter().enumerate() {
            p_index[n as usize] = j as i32;
        }
        let mut face_index = vec![-1i32; mesh.nodes.len()];
        for (i, &n) in comp.rows.iter().enumerate() {
            face_index[n as usize] = i as i32;
        }
        // Equal blocks, the last rank the remainder: the row layout the dense ScaLAPACK
        // Jacobian requires.
        let ranges = crate::mesh::equal_blocks(n_p + 1, nranks);
        CondensedLayout { n_p, ranges, p_index, face_index }
    }
    pub fn total(&self) -> usize {
        self.n_p + 1
    }
    pub fn local(&self, rank: usize) -> usize {
        self.ranges[rank + 1] - self.ranges[rank]
    }
    pub fn h0(&self) -> usize {
        self.n_p
    }
}

struct Element {
    /// Face index of the 6 nodes.
    face: [usize; 6],
    /// The same as the cavitation multiplier's node ids.
    ids: [u32; 6],
    /// The pressure unknowns each of the 6 nodes takes its pressure from, with weights
    /// (unknown -1 or weight 0: none; the Dirichlet edges have no unknown): the node's own
    /// unknown with weight 1. Kept as a prolongation T (pressure unknowns to nodal
    /// pressures) so that another pressure space changes only this table.
    t: [[(i32, f64); 2]; 6],
    verts: [[f64; 2]; 3],
    vel: [[f64; 2]; 3],
    /// Load weights (integral of each pressure basis function over the element).
    w: [f64; 6],
    /// Touches a row this rank owns.
    mine: bool,
}

/// One element's residual and Jacobian on its pressure unknowns (T^T R, T^T dR/dP T and
/// T^T dR/dH, with T the element's pressure prolongation): rows `dofs[..n]`.
struct Projected {
    n: usize,
    dofs: [i32; 6],
    r: [f64; 6],
    /// d r_a / d P_{dofs\[b\]}.
    dp: [[f64; 6]; 6],
    /// d r_a / d H at the element's 6 face nodes.
    dh: [[f64; 6]; 6],
}

impl Element {
    /// Projects the element's nodal residual and Jacobian onto its pressure unknowns.
    fn project(&self, out: &ElementOut) -> Projected {
        let mut pr = Projected { n: 0, dofs: [-1; 6], r: [0.0; 6], dp: [[0.0; 6]; 6], dh: [[0.0; 6]; 6] };
        // Each node's (position among the element's unknowns, weight) entries.
        let mut slots: [[Option<(usize, f64)>; 2]; 6] = [[None; 2]; 6];
        for (k, slot) in slots.iter_mut().enumerate() {
            for (m, (d, w)) in self.entries(k).enumerate() {
                let a = match pr.dofs[..pr.n].iter().position(|&x| x == d) {
                    Some(a) => a,
                    None => {
                        pr.dofs[pr.n] = d;
                        pr.n += 1;
                        pr.n - 1
                    }
                };
                slot[m] = Some((a, w));
            }
        }
        for (i, si) in slots.iter().enumerate() {
            for &(a, wa) in si.iter().flatten() {
                pr.r[a] += wa * out.r[i];
                for (k, sk) in slots.iter().enumerate() {
                    pr.dh[a][k] += wa * out.dr_dh[i][k];
                    for &(b, wb) in sk.iter().flatten() {
                        pr.dp[a][b] += wa * wb * out.dr_dp[i][k];
                    }
                }
            }
        }
        pr
    }

    /// The (pressure unknown, weight) entries local node `k` takes its pressure from,
    /// without the padding and the Dirichlet edges' missing unknowns.
    fn entries(&self, k: usize) -> impl Iterator<Item = (i32, f64)> + '_ {
        self.t[k].iter().copied().filter(|&(d, w)| d >= 0 && w != 0.0)
    }

    /// The element's pressure unknowns, node by node (an unknown shared by several nodes
    /// appears once per node).
    fn dofs(&self) -> impl Iterator<Item = i32> + '_ {
        (0..6).flat_map(|k| self.entries(k).map(|(d, _)| d))
    }

    /// Whether any of the element's pressure unknowns satisfies `f`.
    fn any_dof(&self, f: impl Fn(i32) -> bool) -> bool {
        self.dofs().any(f)
    }
}

/// The block of the dense condensed Jacobian one rank fills: its rows and columns (global
/// indices), their positions in the block (-1: not in it), and the compliance restricted
/// to the block's columns (None when the block has every column: `Compliance::c` itself).
struct FillBlock {
    rows: Vec<usize>,
    cols: Vec<usize>,
    row_pos: Vec<i32>,
    col_pos: Vec<i32>,
    c_cols: Option<Vec<f64>>,
}

impl FillBlock {
    fn new(rows: Vec<usize>, cols: Vec<usize>, comp: &Compliance, total: usize) -> Self {
        let positions = |ix: &[usize]| {
            let mut pos = vec![-1i32; total];
            for (k, &i) in ix.iter().enumerate() {
                pos[i] = k as i32;
            }
            pos
        };
        let (row_pos, col_pos) = (positions(&rows), positions(&cols));
        let np = comp.cols.len();
        let all = cols.len() == total && cols.iter().enumerate().all(|(k, &c)| k == c);
        // The H0 column has no compliance: 0 in the restricted copy.
        let c_cols = (!all && !comp.is_rigid())
            .then(|| comp.c.chunks_exact(np).flat_map(|crow| cols.iter().map(|&c| if c < np { crow[c] } else { 0.0 })).collect());
        FillBlock { rows, cols, row_pos, col_pos, c_cols }
    }

    /// Position in the block of row `d` (None: -1, or not in the block).
    fn row_of(&self, d: i32) -> Option<usize> {
        Self::pos(&self.row_pos, d)
    }

    /// Position in the block of column `d` (None: -1, or not in the block).
    fn col_of(&self, d: i32) -> Option<usize> {
        Self::pos(&self.col_pos, d)
    }

    fn pos(table: &[i32], d: i32) -> Option<usize> {
        (d >= 0 && table[d as usize] >= 0).then(|| table[d as usize] as usize)
    }

    /// Compliance row of face node `f` on the block's columns (with every column, the P
    /// columns only: zipping stops before H0).
    fn c_row<'c>(&'c self, comp: &'c Compliance, f: usize) -> &'c [f64] {
        match &self.c_cols {
            Some(c) => &c[f * self.cols.len()..(f + 1) * self.cols.len()],
            None => {
                let np = comp.cols.len();
                &comp.c[f * np..(f + 1) * np]
            }
        }
    }
}

/// Slope of the cavitation penalty in the Jacobian at P: exact for the smoothed law; with
/// the plain min(P, 0) (no smoothing) at least 1, so the kink's active set includes P >= 0.
fn penalty_slope(p: f64) -> f64 {
    penalty_law(p).1.max(if CAVITATION_SMOOTHING > 0.0 { 0.0 } else { 1.0 })
}

/// The condensed EHL problem on one rank (all data replicated; rows distributed).
pub struct CondensedSystem<'a> {
    pub comp: &'a Compliance,
    /// Mesh: node coordinates for messages (domain errors, where the film closed) and
    /// developer diagnostics.
    pub debug_mesh: Option<&'a Mesh>,
    pub layout: CondensedLayout,
    pub rank: usize,
    pub params: EhlParams,
    pub lubricant: Lubricant,
    elements: Vec<Element>,
    /// Gradient-jump terms of every interior contact edge (on the pressure unknowns).
    jumps: Vec<JumpRows>,
    /// Nodal area (a sixth of each P2 triangle at the node) of each pressure unknown.
    p_area: Vec<f64>,
    /// The cavitation multipliers (face nodes as ids), when the scene's cavitation is the
    /// complementarity form.
    multipliers: Option<Multipliers>,
    /// Each face node's pressure unknowns with weights (the elements' T, node by node).
    face_t: Vec<[(i32, f64); 2]>,
    /// The block of the dense Jacobian this rank fills (default: its rows, all columns).
    fill: FillBlock,
    /// Rigid gap at each face node.
    gap: Vec<f64>,
    row_scale: Vec<f64>,
    pub residual_evals: usize,
    pub jacobian_evals: usize,
    pub step_limits: Vec<f64>,
    /// Where the film closed in the last Newton solve (X, Z in units of a), if it did: see
    /// [`FILM_COLLAPSE`].
    pub collapse: Option<[f64; 2]>,
    /// Freeze H0 at this value (the load row becomes H0 - value = 0): the pressure of a
    /// given film, used to build a consistent start with rigid solids.
    pub fixed_h0: Option<f64>,
}

impl<'a> CondensedSystem<'a> {
    /// (X, Z) in units of a of face row k (a compliance row), if the mesh is known.
    fn face_xz(&self, k: usize) -> Option<[f64; 2]> {
        self.debug_mesh.map(|m| m.nodes[self.comp.rows[k] as usize]).map(|c| [c[0], c[2]])
    }

    pub fn new(mesh: &Mesh, comp: &'a Compliance, nranks: usize, rank: usize, params: EhlParams, lubricant: Lubricant) -> Self {
        let layout = CondensedLayout::new(mesh, comp, nranks);
        let (lo, hi) = (layout.ranges[rank], layout.ranges[rank + 1].min(layout.n_p));
        let mut node_area = vec![0.0; comp.rows.len()];
        let mut elements = Vec::new();
        let owned = |d: i32| d >= 0 && (d as usize) >= lo && (d as usize) < hi;
        for tri in &mesh.contact_tris {
            let xz = |n: u32| {
                let c = mesh.nodes[n as usize];
                [c[0], c[2]]
            };
            let face = tri.map(|n| layout.face_index[n as usize] as usize);
            let p = tri.map(|n| layout.p_index[n as usize]);
            let verts = [xz(tri[0]), xz(tri[1]), xz(tri[2])];
            let area = tri_area(&verts);
            for &f in &face {
                node_area[f] += area / 6.0;
            }
            let t: [[(i32, f64); 2]; 6] = std::array::from_fn(|k| [(p[k], 1.0), (-1, 0.0)]);
            let mut e = Element {
                face,
                ids: face.map(|f| f as u32),
                t,
                verts,
                vel: verts.map(|v| (params.velocity)(v[0], v[1])),
                w: p2_tri_weights(area),
                mine: false,
            };
            e.mine = e.any_dof(owned);
            elements.push(e);
        }
        let c_j = params.stabilisation.jump;
        let jumps = super::system::jump_terms_of(mesh, c_j, |_| true)
            .into_iter()
            .map(|(_, _, edge)| {
                let rows = edge.nodes.iter().map(|&n| layout.p_index[n as usize]).collect();
                JumpRows::new(edge, rows, c_j, &*params.velocity)
            })
            .collect();
        let mut face_t = vec![[(-1, 0.0); 2]; comp.rows.len()];
        for e in &elements {
            for k in 0..6 {
                face_t[e.face[k]] = e.t[k];
            }
        }
        let multipliers = params.stabilisation.complementarity.then(|| {
            let ids: Vec<[u32; 6]> = elements.iter().map(|e: &Element| e.ids).collect();
            let areas: Vec<f64> = elements.iter().map(|e| tri_area(&e.verts)).collect();
            Multipliers::new(&ids, &areas)
        });
        let p_face: Vec<usize> = comp.cols.iter().map(|&n| layout.face_index[n as usize] as usize).collect();
        let p_area = p_face.iter().map(|&f| node_area[f]).collect();
        let fill = FillBlock::new((lo..layout.ranges[rank + 1]).collect(), (0..layout.total()).collect(), comp, layout.total());
        let gap = comp.rows.iter().map(|&n| super::layout::Layout::gap(mesh.nodes[n as usize])).collect();
        let row_scale = vec![1.0; layout.total()];
        CondensedSystem {
            comp,
            debug_mesh: None,
            layout,
            rank,
            params,
            lubricant,
            elements,
            jumps,
            p_area,
            multipliers,
            face_t,
            fill,
            gap,
            row_scale,
            residual_evals: 0,
            jacobian_evals: 0,
            step_limits: Vec::new(),
            collapse: None,
            fixed_h0: None,
        }
    }

    fn owned(&self) -> (usize, usize) {
        (self.layout.ranges[self.rank], self.layout.ranges[self.rank + 1])
    }

    /// The scaled Reynolds residual (with the penalty) of rows `lo..hi` (the load row, if
    /// among them, left 0).
    fn scaled_reynolds(&self, x: &[f64], h: &[f64], lo: usize, hi: usize) -> Vec<f64> {
        let mut r = vec![0.0; hi - lo];
        let row = |d: i32| (d >= 0 && (d as usize) >= lo && (d as usize) < hi).then(|| d as usize - lo);
        let fluid = self.fluid();
        for e in self.elements.iter().filter(|e| e.any_dof(|d| row(d).is_some())) {
            let p = Self::element_p(x, e);
            let he = e.face.map(|f| h[f]);
            let pr = e.project(&self.eval(e, &p, &he, &fluid));
            for a in 0..pr.n {
                if let Some(l) = row(pr.dofs[a]) {
                    r[l] += pr.r[a];
                }
            }
        }
        for jt in &self.jumps {
            for (a, &d) in jt.rows.iter().enumerate() {
                if let Some(l) = row(d) {
                    r[l] += jt.residual_row(a, x);
                }
            }
        }
        for j in lo..hi.min(self.layout.n_p) {
            r[j - lo] += self.params.penalty * self.p_area[j] * penalty_law(x[j]).0;
        }
        for (i, v) in r.iter_mut().enumerate() {
            *v *= self.row_scale[lo + i];
        }
        r
    }

    /// Per pressure row, the derivatives (in P and in the scaled residual) of the
    /// complementarity function at `x` (all rows; (0, 1) without complementarity).
    fn complementarity_slopes(&self, x: &[f64], h: &[f64]) -> Vec<(f64, f64)> {
        let np = self.layout.n_p;
        if !self.params.stabilisation.complementarity {
            return vec![(0.0, 1.0); np];
        }
        let r = self.scaled_reynolds(x, h, 0, np);
        (0..np).map(|j| complementarity(x[j], r[j])).map(|(_, dp, df)| (dp, df)).collect()
    }

    /// The pressure unknowns among this rank's rows.
    fn owned_p(&self) -> std::ops::Range<usize> {
        let (lo, hi) = self.owned();
        lo..hi.min(self.layout.n_p)
    }

    /// Fill the dense Jacobian's block (`rows` x `cols`, global indices) on this rank
    /// instead of its own rows and all columns: the share a `MATSCALAPACK` stores.
    pub fn set_fill_block(&mut self, rows: Vec<usize>, cols: Vec<usize>) {
        self.fill = FillBlock::new(rows, cols, self.comp, self.layout.total());
    }

    /// The load integral of the pressure of x (dimensionless).
    pub fn load(&self, x: &[f64]) -> f64 {
        self.elements
            .iter()
            .map(|e| {
                let p = Self::element_p(x, e);
                (0..6).map(|k| e.w[k] * p[k]).sum::<f64>()
            })
            .sum()
    }

    /// Local row of pressure unknown `d` if this rank owns it (None for -1 or another rank's).
    fn own_row(&self, d: i32) -> Option<usize> {
        let (lo, hi) = self.owned();
        (d >= 0 && (d as usize) >= lo && (d as usize) < hi).then(|| d as usize - lo)
    }

    /// Film H at every face node for the iterate x = (P, H0).
    pub fn film(&self, x: &[f64]) -> Vec<f64> {
        let h0 = x[self.layout.h0()];
        let uy = self.comp.apply(&x[..self.layout.n_p]);
        uy.iter().zip(&self.gap).map(|(u, g)| h0 + g - u).collect()
    }

    /// U_y at every face node.
    pub fn uy(&self, x: &[f64]) -> Vec<f64> {
        self.comp.apply(&x[..self.layout.n_p])
    }

    fn fluid(&self) -> Fluid<'_> {
        self.lubricant.fluid(self.params.lambda_bar)
    }

    /// Residual and Jacobian of one P2 element.
    fn eval(&self, e: &Element, p: &[f64; 6], h: &[f64; 6], fluid: &Fluid) -> ElementOut {
        let stab = &self.params.stabilisation;
        match &self.multipliers {
            Some(m) if stab.complementarity && stab.supg => {
                reynolds_element_with_multiplier(&e.verts, p, h, &e.vel, fluid, stab, &m.of(&e.ids))
            }
            _ => reynolds_element(&e.verts, p, h, &e.vel, fluid, stab),
        }
    }

    /// Element `e` with its fields, as the multiplier sees it.
    fn face_element<'e>(x: &[f64], h: &[f64], e: &'e Element) -> FaceElement<'e> {
        FaceElement { nodes: &e.ids, verts: &e.verts, vel: &e.vel, p: Self::element_p(x, e), h: e.face.map(|f| h[f]) }
    }

    /// Measures the nodal cavitation multipliers at `x` (film `h`) when SUPG needs them.
    fn measure_multipliers(&mut self, x: &[f64], h: &[f64]) {
        if !(self.params.stabilisation.complementarity && self.params.stabilisation.supg) {
            return;
        }
        let Some(mut m) = self.multipliers.take() else { return };
        let fluid = self.lubricant.fluid(self.params.lambda_bar);
        m.evaluate(self.elements.len(), |t| Self::face_element(x, h, &self.elements[t]), &fluid, &self.params.stabilisation);
        self.multipliers = Some(m);
    }

    /// The multiplier's part of element `e`'s rows (`dr_dm` from its output): calls
    /// `add(row unknown, column face node, dR/dP, dR/dH)` with the rows projected on the
    /// pressure unknowns and the columns left at face nodes.
    fn chain_multiplier(
        &self,
        x: &[f64],
        h: &[f64],
        e: &Element,
        dr_dm: &[[f64; 6]; 6],
        fluid: &Fluid,
        mut add: impl FnMut(i32, usize, f64, f64),
    ) {
        let Some(m) = &self.multipliers else { return };
        m.chain(
            &e.ids,
            dr_dm,
            |t| Self::face_element(x, h, &self.elements[t]),
            fluid,
            &self.params.stabilisation,
            |i, f, dp, dh| {
                for (d, w) in e.entries(i) {
                    add(d, f as usize, w * dp, w * dh);
                }
            },
        );
    }

    /// The element's 6 nodal pressures (T P on the element).
    fn element_p(x: &[f64], e: &Element) -> [f64; 6] {
        std::array::from_fn(|k| e.entries(k).map(|(d, w)| w * x[d as usize]).sum())
    }

    /// Local preallocation: dense (every owned row full) with an elastic compliance;
    /// with rigid solids the Reynolds stencil (element neighbours and H0) and the dense
    /// load row.
    pub fn preallocation(&self) -> (Vec<i32>, Vec<i32>) {
        let nl = self.layout.local(self.rank);
        let n = self.layout.total();
        if !self.comp.is_rigid() {
            return (vec![nl as i32; nl], vec![(n - nl) as i32; nl]);
        }
        let (lo, hi) = self.owned();
        let np = self.layout.n_p;
        let mut cols: Vec<std::collections::BTreeSet<usize>> = vec![Default::default(); hi - lo];
        for e in self.elements.iter().filter(|e| e.mine) {
            let dofs: Vec<i32> = e.dofs().collect();
            for r in e.dofs() {
                let Some(l) = self.own_row(r) else { continue };
                cols[l].insert(np);
                cols[l].extend(dofs.iter().map(|&d| d as usize));
            }
        }
        for jt in &self.jumps {
            for &r in &jt.rows {
                let Some(l) = self.own_row(r) else { continue };
                cols[l].extend(jt.rows.iter().filter(|&&d| d >= 0).map(|&d| d as usize));
            }
        }
        if hi > np {
            cols[np - lo] = (0..=np).collect();
        }
        let d = cols.iter().map(|c| c.iter().filter(|&&j| j >= lo && j < hi).count() as i32).collect::<Vec<_>>();
        let o = cols.iter().zip(&d).map(|(c, &dd)| c.len() as i32 - dd).collect();
        (d, o)
    }

    /// The Jacobian with rigid solids (H = H0 + gap): sparse, element by element.
    fn jacobian_rigid(&mut self, x: &[f64], j: &Matrix) -> Result<()> {
        let np = self.layout.n_p;
        let (_, hi) = self.owned();
        let h = self.film(x);
        self.measure_multipliers(x, &h);
        let fluid = self.fluid();
        let slopes = self.complementarity_slopes(x, &h);
        j.zero()?;
        for e in self.elements.iter().filter(|e| e.mine) {
            let p = Self::element_p(x, e);
            let he = e.face.map(|f| h[f]);
            let out = self.eval(e, &p, &he, &fluid);
            let mut err = Ok(());
            self.chain_multiplier(x, &h, e, &out.dr_dm, &fluid, |d, f, dp, dh| {
                if self.own_row(d).is_none() || err.is_err() {
                    return;
                }
                let s = self.row_scale[d as usize] * slopes[d as usize].1;
                let (mut cols, mut vals): (Vec<i32>, Vec<f64>) =
                    self.face_t[f].iter().filter(|&&(c, w)| c >= 0 && w != 0.0).map(|&(c, w)| (c, s * w * dp)).unzip();
                cols.push(np as i32);
                vals.push(s * dh);
                err = j.add_values(&[d], &cols, &vals);
            });
            err?;
            let pr = e.project(&out);
            for a in 0..pr.n {
                let Some(_) = self.own_row(pr.dofs[a]) else { continue };
                let r = pr.dofs[a] as usize;
                let s = self.row_scale[r] * slopes[r].1;
                let mut cols = Vec::with_capacity(7);
                let mut vals = Vec::with_capacity(7);
                for b in 0..pr.n {
                    cols.push(pr.dofs[b]);
                    vals.push(s * pr.dp[a][b]);
                }
                // dH/dH0 = 1 at every node.
                cols.push(np as i32);
                vals.push(s * pr.dh[a].iter().sum::<f64>());
                j.add_values(&[r as i32], &cols, &vals)?;
            }
        }
        for jt in &self.jumps {
            for (a, &r) in jt.rows.iter().enumerate().filter(|&(_, &r)| self.own_row(r).is_some()) {
                let s = self.row_scale[r as usize] * slopes[r as usize].1;
                let vals: Vec<f64> = (0..jt.rows.len()).map(|b| s * jt.entry(a, b)).collect();
                j.add_values(&[r], &jt.rows, &vals)?;
            }
        }
        for jn in self.owned_p() {
            let dv = penalty_slope(x[jn]);
            let (dp, df) = slopes[jn];
            j.add_values(&[jn as i32], &[jn as i32], &[self.row_scale[jn] * df * self.params.penalty * self.p_area[jn] * dv + dp])?;
        }
        if hi > np {
            if self.fixed_h0.is_some() {
                j.add_values(&[np as i32], &[np as i32], &[1.0])?;
            } else {
                for e in &self.elements {
                    let (cols, vals): (Vec<i32>, Vec<f64>) = (0..6).flat_map(|k| e.entries(k).map(move |(d, w)| (d, w * e.w[k]))).unzip();
                    j.add_values(&[np as i32], &cols, &vals)?;
                }
            }
        }
        Ok(())
    }
}

impl EhlProblem for CondensedSystem<'_> {
    fn set_operating(&mut self, lambda_bar: f64, lubricant: Lubricant, penalty: f64, complementarity: bool) {
        self.params.set_operating(lambda_bar, penalty, complementarity);
        self.lubricant = lubricant;
    }

    fn take_collapse(&mut self) -> Option<[f64; 2]> {
        self.collapse.take()
    }

    fn h0_index(&self) -> usize {
        self.layout.h0()
    }

    fn set_velocity(&mut self, velocity: Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync>) -> bool {
        for e in &mut self.elements {
            e.vel = e.verts.map(|v| velocity(v[0], v[1]));
        }
        for jt in &mut self.jumps {
            jt.set_velocity(self.params.stabilisation.jump, &*velocity);
        }
        self.params.velocity = velocity;
        true
    }

    /// Row scaling as in the monolithic system: each Reynolds row by the inverse of its
    /// dR/dP diagonal at `x` (constant afterwards).
    fn scale_rows(&mut self, x: &[f64]) -> Result<()> {
        let h = self.film(x);
        let fluid = self.fluid();
        // Every row's scale (not only this rank's rows): the dense Jacobian's block may hold
        // any row.
        let mut diag = vec![0.0; self.layout.total()];
        for e in &self.elements {
            let p = Self::element_p(x, e);
            let he = e.face.map(|f| h[f]);
            let pr = e.project(&self.eval(e, &p, &he, &fluid));
            for a in 0..pr.n {
                diag[pr.dofs[a] as usize] += pr.dp[a][a].abs();
            }
        }
        for jt in &self.jumps {
            for (a, &d) in jt.rows.iter().enumerate().filter(|(_, &d)| d >= 0) {
                diag[d as usize] += jt.entry(a, a);
            }
        }
        for (j, d) in diag.iter().enumerate().take(self.layout.n_p) {
            let v = d.abs() + self.params.row_scale_floor();
            self.row_scale[j] = if v > 0.0 { 1.0 / v } else { 1.0 };
        }
        Ok(())
    }
}

impl Problem for CondensedSystem<'_> {
    fn residual(&mut self, x: &[f64], f: &Vector) -> Result<Eval> {
        self.residual_evals += 1;
        let h = self.film(x);
        // Every rank holds the same iterate and the same compliance: the domain check
        // agrees everywhere without communication.
        if let Some(k) = h.iter().position(|v| !(*v > 0.0) || !v.is_finite()) {
            let at = self.face_xz(k).map(|c| format!(" (X, Z) = ({:.3}, {:.3})", c[0], c[1])).unwrap_or_default();
            return Ok(Eval::Domain(format!("film thickness H = {:.3e} at face node {}{at}", h[k], self.comp.rows[k])));
        }
        if let Some(why) = self.lubricant.out_of_range(x[..self.layout.n_p].iter().copied()) {
            return Ok(Eval::Domain(why));
        }
        let (lo, hi) = self.owned();
        self.measure_multipliers(x, &h);
        let mut r = self.scaled_reynolds(x, &h, lo, hi);
        if self.params.stabilisation.complementarity {
            for j in self.owned_p() {
                r[j - lo] = complementarity(x[j], r[j - lo]).0;
            }
        }
        if hi > self.layout.n_p {
            // Load balance, on the rank that owns H0.
            r[self.layout.h0() - lo] = match self.fixed_h0 {
                Some(h0) => x[self.layout.h0()] - h0,
                None => self.load(x) - self.params.load,
            };
        }
        if crate::ehl_options::get().monitor {
            if let Some(mesh) = self.debug_mesh {
                let np = self.layout.n_p;
                let mut order: Vec<usize> = (0..r.len()).filter(|&i| lo + i < np).collect();
                order.sort_by(|&a, &b| r[b].abs().partial_cmp(&r[a].abs()).unwrap());
                let norm: f64 = r.iter().map(|v| v * v).sum::<f64>().sqrt();
                let mut msg = format!("ehl_monitor: rank {} |r| = {norm:.3e}; worst:", self.rank);
                for &i in order.iter().take(4) {
                    let n = self.comp.cols[lo + i];
                    let c = mesh.nodes[n as usize];
                    msg += &format!(
                        " [{:.3e} at ({:.3},{:.3}) P={:.4} H={:.4}]",
                        r[i],
                        c[0],
                        c[2],
                        x[lo + i],
                        h[self.layout.face_index[n as usize] as usize]
                    );
                }
                eprintln!("{msg}");
                if self.rank == 0 {
                    let hc = mesh.locate_contact(0.0, 0.0).map_or(f64::NAN, |(t, b)| {
                        crate::fem::p2_tri_eval(&mesh.contact_tris[t].map(|n| h[self.layout.face_index[n as usize] as usize]), b)
                    });
                    let hm = h.iter().copied().fold(f64::INFINITY, f64::min);
                    eprintln!("ehl_monitor: iterate films hc = {hc:.6e} min nodal H = {hm:.6e} (H)");
                }
            }
        }
        let idx: Vec<i32> = (lo as i32..hi as i32).collect();
        f.set_values(&idx, &r, true)?;
        Ok(Eval::Ok)
    }

    fn clip_step(&mut self, x: &[f64], y: &mut [f64]) -> Result<usize> {
        let Some(floor) = pressure_step_floor() else { return Ok(0) };
        let mut n = 0;
        for i in 0..self.layout.n_p {
            let c = clip_pressure_step(x[i], y[i], floor);
            if c != y[i] {
                y[i] = c;
                n += 1;
            }
        }
        Ok(n)
    }

    fn limit_step(&mut self, x: &[f64], y: &[f64]) -> Result<f64> {
        const FILM_KEEP: f64 = 0.2;
        if !crate::ehl_options::get().film_limiter {
            return Ok(1.0);
        }
        let h = self.film(x);
        let dh0 = y[self.layout.h0()];
        // x_new = x - y: H_new = H - (dh0 - duy)
        let dh: Vec<f64> = self.comp.apply(&y[..self.layout.n_p]).iter().map(|duy| dh0 - duy).collect();
        let (s, binding) = film_step_limit(&h, &dh, FILM_KEEP);
        self.step_limits.push(s);
        // Newton keeps pushing the film at one node through zero: the limiter has shrunk it
        // to nothing. Stop this solve (a zero step fails the line search at once) instead of
        // crawling on (21-30 iterations of steps of 1e-3 .. 1e-14 on the strong-spin scene).
        if let Some(k) = binding.filter(|&k| h[k] < FILM_COLLAPSE) {
            self.collapse = Some(self.face_xz(k).unwrap_or([f64::NAN; 2]));
            return Ok(0.0);
        }
        if crate::ehl_options::get().monitor && self.rank == 0 {
            let k = (0..h.len()).min_by(|&a, &b| h[a].partial_cmp(&h[b]).unwrap()).unwrap();
            let at = self.face_xz(k).map(|c| format!(" (X, Z) = ({:.3}, {:.3})", c[0], c[1])).unwrap_or_default();
            eprintln!(
                "ehl_monitor: limiter {s:.3e}; H0 = {:.4e} dH0 = {dh0:.3e}; min H = {:.3e} at node {}{at}",
                x[self.layout.h0()],
                h[k],
                self.comp.rows[k]
            );
        }
        Ok(s)
    }

    fn jacobian(&mut self, x: &[f64], j: &Matrix) -> Result<()> {
        self.jacobian_evals += 1;
        if self.comp.is_rigid() {
            return self.jacobian_rigid(x, j);
        }
        let np = self.layout.n_p;
        let h = self.film(x);
        self.measure_multipliers(x, &h);
        let fluid = self.fluid();
        let fb = &self.fill;
        let ncl = fb.cols.len();
        let mut buf = vec![0.0; fb.rows.len() * ncl];
        let h0_col = fb.col_of(np as i32);
        // dR/dH per (row, face node), summed over the elements and the multiplier's chain
        // before each face node's compliance row is subtracted once: each subtraction is a
        // dense row update, and the chain reaches the same face nodes from several
        // cavitated nodes (docs/numerics.md, "Cavitation as complementarity").
        let mut dr_dh: Vec<Vec<(usize, f64)>> = vec![Vec::new(); fb.rows.len()];
        let mut add_dh = |l: usize, f: usize, g: f64| match dr_dh[l].iter_mut().find(|(k, _)| *k == f) {
            Some((_, v)) => *v += g,
            None => dr_dh[l].push((f, g)),
        };
        for e in &self.elements {
            if !e.any_dof(|d| fb.row_of(d).is_some()) {
                continue;
            }
            let p = Self::element_p(x, e);
            let he = e.face.map(|f| h[f]);
            let out = self.eval(e, &p, &he, &fluid);
            self.chain_multiplier(x, &h, e, &out.dr_dm, &fluid, |d, f, dp, dh| {
                let Some(l) = fb.row_of(d) else { return };
                let row = &mut buf[l * ncl..(l + 1) * ncl];
                for &(c, w) in self.face_t[f].iter().filter(|&&(c, w)| c >= 0 && w != 0.0) {
                    if let Some(c) = fb.col_of(c) {
                        row[c] += w * dp;
                    }
                }
                if dh != 0.0 {
                    add_dh(l, f, dh);
                    if let Some(c) = h0_col {
                        row[c] += dh;
                    }
                }
            });
            let pr = e.project(&out);
            for a in 0..pr.n {
                let Some(l) = fb.row_of(pr.dofs[a]) else { continue };
                let row = &mut buf[l * ncl..(l + 1) * ncl];
                for b in 0..pr.n {
                    if let Some(c) = fb.col_of(pr.dofs[b]) {
                        row[c] += pr.dp[a][b];
                    }
                }
                for k in 0..6 {
                    // H = H0 + gap - U_y with U_y = C P: dH/dP = -C, dH/dH0 = 1.
                    let g = pr.dh[a][k];
                    if g != 0.0 {
                        add_dh(l, e.face[k], g);
                        if let Some(c) = h0_col {
                            row[c] += g;
                        }
                    }
                }
            }
        }
        for (l, terms) in dr_dh.iter().enumerate() {
            let row = &mut buf[l * ncl..(l + 1) * ncl];
            for &(f, g) in terms {
                for (a, c) in row.iter_mut().zip(fb.c_row(self.comp, f)) {
                    *a -= g * c;
                }
            }
        }
        for jt in &self.jumps {
            for (a, &d) in jt.rows.iter().enumerate() {
                let Some(l) = fb.row_of(d) else { continue };
                for (b, &e) in jt.rows.iter().enumerate() {
                    if let Some(c) = fb.col_of(e) {
                        buf[l * ncl + c] += jt.entry(a, b);
                    }
                }
            }
        }
        let slopes = self.complementarity_slopes(x, &h);
        for (l, &jn) in fb.rows.iter().enumerate().filter(|(_, &r)| r < np) {
            let row = &mut buf[l * ncl..(l + 1) * ncl];
            let area = self.p_area[jn];
            let diag = fb.col_of(jn as i32);
            if let Some(c) = diag {
                row[c] += self.params.penalty * area * penalty_slope(x[jn]);
            }
            // Complementarity: phi(P, F) has the row d phi/dF dF/dx + d phi/dP e_j.
            let (dp, df) = slopes[jn];
            let s = self.row_scale[jn] * df;
            row.iter_mut().for_each(|v| *v *= s);
            if let Some(c) = diag {
                row[c] += dp;
            }
        }
        if let Some(l) = fb.row_of(np as i32) {
            // Load row: integral of P.
            let row = &mut buf[l * ncl..(l + 1) * ncl];
            for e in &self.elements {
                for k in 0..6 {
                    for &(d, w) in &e.t[k] {
                        if let Some(c) = fb.col_of(d) {
                            row[c] += w * e.w[k];
                        }
                    }
                }
            }
        }
        let rows: Vec<i32> = fb.rows.iter().map(|&r| r as i32).collect();
        let cols: Vec<i32> = fb.cols.iter().map(|&c| c as i32).collect();
        j.set_values(&rows, &cols, &buf)?;
        Ok(())
    }
}
