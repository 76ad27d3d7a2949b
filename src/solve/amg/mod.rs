//! Conjugate gradients preconditioned by smoothed-aggregation algebraic multigrid
//! (Vaněk, Mandel & Brezina, *Computing* 56, 1996), for SPD systems too large to factor.
//!
//! Set-up, level by level until at most [`AmgOptions::coarse_size`] unknowns remain:
//! 1. strength of connection: `j` is a strong neighbour of `i` when
//!    `−a_ij ≥ θ √(m_i m_j)`, `m_i` the largest `−a_ik` of row `i` (`k ≠ i`), θ = 0.4 on
//!    every level — the classical measure of Ruge & Stüben (relative to the row's
//!    largest coupling), made symmetric. Measured against the diagonal instead (Vaněk
//!    et al.'s `|a_ij| ≥ ε √(a_ii a_jj)`), no ε serves both kinds of cell a scene has.
//!    A cube's Q1 stiffness couples a node to its edge and corner neighbours with 1/16
//!    and 1/32 of its diagonal and to its face neighbours with 0, so ε must be small;
//!    a thin part's cells (aspect 5) couple it to the through-thickness neighbour with
//!    −0.44 of its diagonal, to the edge neighbours across the thickness with −0.12,
//!    to its corner neighbours with −0.03 and to the in-plane face neighbours with
//!    +0.22. A small ε makes isotropic aggregates there, which cannot represent the
//!    error a point smoother leaves (smooth through the thickness, oscillating in the
//!    plane); against the row's largest coupling the thin cells aggregate across their
//!    thickness only — if θ is above the edge neighbours' 0.12/0.44 = 0.27 of the
//!    largest, and below a cube's corner neighbours' 1/2 of it (its edge ones are the
//!    largest), so that a cube still aggregates with all 26 neighbours. θ = 0.4 sits
//!    between. At θ = 0.25 the thin cells aggregated with their edge neighbours too: the
//!    electronics warm-up (die cells of aspect 5) took 29–30 CG iterations per early
//!    step instead of 16–17, at refine 13; the cube meshes of the tied and gap
//!    benchmarks took 17 and 14 iterations either way (16 and 14 at 0.4).
//!    Positive couplings are never strong;
//! 2. aggregation (the paper's three passes): seed aggregates from nodes whose strong
//!    neighbourhood is still free, attach leftovers to a neighbouring aggregate, group
//!    the rest; nodes with no strong neighbour (e.g. rows eliminated by Dirichlet
//!    conditions, which the smoother solves exactly) join no aggregate;
//! 3. tentative prolongator `P̂` = aggregate indicator (the constant is the near null
//!    space of a scalar diffusion operator), smoothed `P = (I − ω D_F⁻¹A_F) P̂` with
//!    `ω = 4/(3 ρ(D_F⁻¹A_F))`, where `A_F` is `A` with its positive off-diagonal
//!    couplings lumped onto the diagonal (Vaněk et al.'s filtered matrix; `A_F = A`
//!    for an M-matrix — why, at `coarsen::filtered_diagonal`). ρ is estimated by at
//!    most ten Lanczos steps (fewer once the estimate settles), except on the finest
//!    level of a hierarchy that serves one solve, which takes Gershgorin's bound
//!    ([`FineRadius`]). P is then truncated: in each row the entries below
//!    [`AmgOptions::truncation`] of its largest are dropped and the rest scaled to keep
//!    the row sum (so P still carries the constants);
//! 4. Galerkin coarse operator `A_c = Pᵀ A P`.
//!
//! The V-cycle smooths with symmetric Gauss–Seidel (forward before, backward after the
//! coarse correction) or damped Jacobi `ω = 4/(3ρ(D⁻¹A))`, plus symmetric Gauss–Seidel
//! sweeps over the rows of a penalty interface alone ([`AmgOptions::penalty_sweeps`]),
//! after the pre- and before the post-smoothing; so the preconditioner is symmetric
//! positive definite and CG applies. The coarsest level is solved by dense Cholesky
//! (or, when coarsening stalls above 2000 unknowns, by 20 symmetric Gauss–Seidel
//! sweeps — the iteration count then grows with the mesh).
//!
//! Mixed precision: the V-cycle reads its matrices (each level's operator, P and R) as
//! single-precision values over the 32-bit structure, and computes in double precision;
//! CG's own product with the fine matrix keeps double precision, so the residual CG
//! stops on is the true one. The sweeps are memory-bound, and 8 bytes per stored entry
//! instead of 12 took the CG of the tied 120:80 boxes (17 iterations either way, the
//! same |x| to 16 digits) from 4.6–5.4 to 2.5–3.5 s of CPU time on a loaded machine. The
//! rounded operators are symmetric (rounding is), so forward and backward sweeps stay
//! adjoint and the preconditioner symmetric; they differ from the exact ones by 6e-8
//! relative, far inside what a smoother's convergence allows (`M + Mᵀ − A` stays
//! positive definite). The double-precision values of P, R and the coarse operators
//! are dropped once the hierarchy is made.
//!
//! The finest level is the exception: with one symmetric Gauss–Seidel sweep on each
//! side (the default), it sweeps with its double-precision values, and its backward
//! sweep also leaves `A z` of the cycle's result `z` in the same pass
//! (`smooth::gauss_seidel_backward_with_product`). CG then makes its product
//! `q = A p` as `A z + β q` (p = z + β p) instead of reading the matrix once more:
//! per iteration the finest matrix is read one and a half times (the forward sweep
//! from zero reads its lower half) instead of two and a half, and it keeps no
//! single-precision copy. On the tied 120:80 boxes (31.7 M entries): 17 iterations
//! before and after, the same error (3.3e-13), the level's 127 MB copy gone.
//!
//! Threads: Gauss–Seidel is sequential, so a level of at least twice
//! [`AmgOptions::block_rows`] rows (the finest, at about 10⁶ unknowns) is cut into
//! consecutive row blocks swept side by side, each Gauss–Seidel inside and reading the
//! other blocks' rows as they were before the sweep (`blocks`). The cut is a function of
//! the matrix, not of the threads, so the bits are the same on any number of them. On
//! the tied 120:80 boxes (two blocks; 17 iterations either way, error 9.7e-14 →
//! 1.0e-13), CG took 2.56 → 1.81 s on two threads and 2.66 → 2.83 s on one.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::{LinearSolver, SolveError, SolveReport, check_rhs, dot, norm};

mod blocks;
mod coarsen;
mod csr;
pub(crate) mod reuse;
mod smooth;
mod successive;

use blocks::Blocks;
use coarsen::{
    aggregate, filtered_diagonal, galerkin, gershgorin_filtered, smoothed_prolongator,
    spectral_radius_dinv_a, spectral_radius_filtered,
};
pub use csr::Csr;
pub use reuse::Served;
use smooth::{
    gauss_seidel, gauss_seidel_backward_with_product, gauss_seidel_from_zero,
    gauss_seidel_from_zero_with_residual, penalty_rows, symmetric_gauss_seidel_rows,
    symmetric_gauss_seidel_rows_with_residual,
};
pub use successive::{KEPT_SOLUTIONS, Successive};

/// The smoother of the V-cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Smoother {
    /// Forward Gauss–Seidel before, backward after the coarse correction (by row
    /// blocks side by side on a large level: [`AmgOptions::block_rows`]).
    SymmetricGaussSeidel,
    /// Damped Jacobi with ω = 4/(3ρ(D⁻¹A)) (parallel).
    Jacobi,
}

/// How the set-up finds ρ(D_F⁻¹A_F) of the finest level, for the damping
/// `ω = 4/(3ρ)` of the smoothed prolongator (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FineRadius {
    /// At most ten Lanczos steps, as on the coarser levels: ρ within a few per cent,
    /// for up to ten products with the matrix.
    Estimate,
    /// Gershgorin's bound, one pass: at most 2 for an assembled conduction matrix, where
    /// ρ is 1.95 near a penalty interface or in stretched cells and 1.5 in a bulk of Q1
    /// cubes; there the prolongator is damped less than it could be and CG takes more
    /// iterations. For a hierarchy that serves one solve. Measured on one thread at
    /// about 1e6 unknowns (medians of three): a conforming box of 100³ cubes 15 → 18
    /// iterations (CG +0.31 s) for a set-up 0.55 s shorter; the tied 120:80 boxes of
    /// `benches/peers.sh` 17 iterations either way, set-up 1.65 → 1.37 s; their
    /// gap-conductance twin 15 → 16, set-up 1.88 → 1.32 s.
    Bound,
}

/// Tuning of [`AmgCg`].
#[derive(Clone, Copy, Debug)]
pub struct AmgOptions {
    /// Strength threshold θ: `j` is a strong neighbour of `i` when `−a_ij` is at least
    /// θ times the geometric mean of the two rows' largest negative couplings (0.4:
    /// why, in the module docs).
    pub strength: f64,
    /// Truncation τ of the smoothed prolongator: in each row of P, entries below τ
    /// times the row's largest are dropped and the rest scaled to keep the row sum
    /// (0 keeps P whole). The small entries come from the smoothing reaching the
    /// neighbouring aggregates; dropping them thins P and with it every coarse
    /// operator, whose Galerkin products are most of the set-up. Measured at 0.1 on
    /// the electronics warm-up at 1.25 M unknowns (aggregates one cell thick in the
    /// die): P 10.6 M → 5.0 M entries, the second level 11.5 M → 7.5 M, the set-up
    /// 6.7 → 3.9 s, for one CG iteration more per step (16 → 17); on the tied 120:80
    /// boxes P 6.7 M → 4.9 M, the set-up 3.0 → 2.3 s, 16 → 17 iterations.
    pub truncation: f64,
    /// Stop coarsening at or below this many unknowns and solve densely.
    pub coarse_size: usize,
    pub max_levels: usize,
    /// Read at set-up (the Jacobi weight is made only for Jacobi).
    pub smoother: Smoother,
    /// Smoothing sweeps before and after the coarse correction.
    pub sweeps: usize,
    /// Symmetric Gauss–Seidel sweeps, after the pre-smoothing and before the
    /// post-smoothing, over the rows of a penalty or Nitsche interface only (rows with
    /// large positive couplings and their neighbours; none in a plain conduction
    /// matrix). See `smooth::penalty_rows`.
    pub penalty_sweeps: usize,
    /// The matrices are symmetric (as CG needs): the V-cycle then makes the residual
    /// after the pre-smoothing within the sweeps' own pass over the matrix. `false` for
    /// the diagonal block of an unsymmetric Jacobian (a GMRES preconditioner), where the
    /// residual is a product with the matrix.
    pub symmetric: bool,
    /// CG stops when ‖r‖/‖b‖ ≤ this.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// How the finest level's ρ for the prolongator is found: the estimate, unless the
    /// hierarchy serves a single solve (then the set-up's products cost more than the
    /// iterations they save).
    pub fine_radius: FineRadius,
    /// Rows per block of the hybrid Gauss–Seidel sweeps: a level of at least twice
    /// this many rows, under the symmetric cycle of one sweep a side, is cut into
    /// consecutive blocks of at least this many that are swept side by side, a row
    /// reading the rows of other blocks as they were before the sweep (`blocks`
    /// module). The cut depends on the matrix alone, so every thread count gives the
    /// same bits. 0 never cuts.
    pub block_rows: usize,
}

impl Default for AmgOptions {
    fn default() -> Self {
        AmgOptions {
            strength: 0.4,
            truncation: 0.1,
            coarse_size: 500,
            max_levels: 12,
            smoother: Smoother::SymmetricGaussSeidel,
            sweeps: 1,
            penalty_sweeps: 1,
            symmetric: true,
            // 1e-8: well below the discretisation error of any mesh this solver is
            // meant for; the direct solvers are there when round-off accuracy matters.
            tolerance: 1e-8,
            max_iterations: 500,
            fine_radius: FineRadius::Estimate,
            block_rows: blocks::BLOCK_ROWS,
        }
    }
}

struct Level {
    a: Csr,
    inv_diag: Vec<f64>,
    /// Per row of `a`, the offset of its diagonal in the row: the sweeps read it
    /// (`Rows::with_diagonal`) rather than search every row for it on every sweep.
    diag_at: Vec<u32>,
    /// ω for Jacobi smoothing (0 when the hierarchy was set up for Gauss–Seidel, which
    /// needs none).
    omega: f64,
    /// Rows that get [`AmgOptions::penalty_sweeps`] more sweeps (ascending): those of
    /// `smooth::penalty_rows`, or on a coarse level where they are most of it, the
    /// aggregates of the finer level's rows.
    penalty_rows: Vec<u32>,
    /// Prolongator to this level from the next coarser one, and its transpose.
    p: Csr,
    r: Csr,
    /// The values of `a`, `p` and `r` in single precision: what the V-cycle reads
    /// (module docs). The double-precision values of `p` and `r`, and of `a` below the
    /// finest level, are dropped once the hierarchy is made; `a32` of a finest level
    /// that sweeps in double precision ([`AmgCg::fine_product`]) is empty.
    a32: Vec<f32>,
    p32: Vec<f32>,
    r32: Vec<f32>,
    x: Vec<f64>,
    b: Vec<f64>,
    res: Vec<f64>,
    /// Scratch: the values of `penalty_rows` before their sweeps.
    saved: Vec<f64>,
    /// The row blocks its sweeps take side by side (a large level under the fused
    /// symmetric cycle), else `None`: swept whole.
    blocks: Option<Blocks>,
}

impl Level {
    /// `times` symmetric Gauss–Seidel sweeps over the penalty rows, with the values the
    /// level sweeps with (single precision, or double on a finest level that keeps no
    /// single copy).
    fn sweep_penalty_rows(&mut self, times: usize) {
        let Level {
            a,
            a32,
            inv_diag,
            penalty_rows,
            x,
            b,
            ..
        } = self;
        for _ in 0..times {
            if a32.is_empty() {
                symmetric_gauss_seidel_rows(a.with_values(&a.val), inv_diag, x, b, penalty_rows);
            } else {
                symmetric_gauss_seidel_rows(a.with_values(a32), inv_diag, x, b, penalty_rows);
            }
        }
    }
}

/// PCG with a smoothed-aggregation AMG V-cycle as preconditioner.
pub struct AmgCg {
    pub options: AmgOptions,
    levels: Vec<Level>,
    /// Dense Cholesky factor (row-major lower) of the coarsest operator.
    coarse: Vec<f64>,
    coarse_n: usize,
    /// A kept hierarchy's state (`reuse`).
    reuse: reuse::Reuse,
    /// Earlier solutions of the finest level's matrix (`successive`).
    earlier: successive::Earlier,
    /// CG's vectors kept between solves: a time step of 1.25 M unknowns otherwise asks
    /// the system for 40 MB of fresh pages each time.
    spare: Vec<Vec<f64>>,
    /// `A z` of the V-cycle's result `z`, made by its last sweep over the finest level
    /// when that level sweeps in double precision ([`AmgCg::fine_product`]).
    product: Vec<f64>,
}

/// Description of the hierarchy: unknowns and stored entries per level.
#[derive(Clone, Debug, PartialEq)]
pub struct Hierarchy {
    pub rows: Vec<usize>,
    pub nnz: Vec<usize>,
}

impl Hierarchy {
    /// Σ nnz(A_l) / nnz(A_0).
    pub fn operator_complexity(&self) -> f64 {
        self.nnz.iter().sum::<usize>() as f64 / self.nnz[0].max(1) as f64
    }
}

impl AmgCg {
    pub fn new(options: AmgOptions) -> Self {
        AmgCg {
            options,
            levels: Vec::new(),
            coarse: Vec::new(),
            coarse_n: 0,
            reuse: reuse::Reuse::default(),
            earlier: successive::Earlier::default(),
            spare: Vec::new(),
            product: Vec::new(),
        }
    }

    /// Whether the finest level sweeps with its double-precision values and its last
    /// sweep leaves `A z` in `product`, which CG then takes for its own product with
    /// the matrix (module docs): a hierarchy of more than one level, set up for one
    /// symmetric Gauss–Seidel sweep on each side. Its finest level keeps no
    /// single-precision values.
    fn fine_product(&self) -> bool {
        self.levels.len() > 1 && self.levels[0].a32.is_empty()
    }

    /// The options under which [`Self::fine_product`] holds once there are two levels.
    fn sweeps_make_product(&self) -> bool {
        let o = &self.options;
        o.symmetric && o.sweeps == 1 && o.smoother == Smoother::SymmetricGaussSeidel
    }

    /// The finest level's single-precision values made again where the options were
    /// changed since the set-up to a cycle that reads them (the options are public);
    /// called before a cycle is run.
    fn fit_fine_values(&mut self) {
        if self.fine_product() && !self.sweeps_make_product() {
            let fine = &mut self.levels[0];
            fine.a32 = fine.a.val.iter().map(|&v| v as f32).collect();
        }
    }

    pub fn hierarchy(&self) -> Hierarchy {
        Hierarchy {
            rows: self.levels.iter().map(|l| l.a.nrows).collect(),
            nnz: self.levels.iter().map(|l| l.a.nnz()).collect(),
        }
    }

    /// [`LinearSolver::factor`] of a borrowed matrix (e.g. a pattern's structure with
    /// values kept apart, which the caller may free once this returns: the hierarchy
    /// holds its own copy).
    pub fn factor_ref(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), SolveError> {
        super::check_finite_ref(a)?;
        self.setup(Csr::from_csc(a))
    }

    /// [`Self::factor_ref`] of a matrix given as its structure and values, taking the
    /// values into the finest level (no copy for a structurally symmetric matrix).
    pub fn factor_values(
        &mut self,
        sym: SymbolicSparseColMatRef<'_, usize>,
        values: Vec<f64>,
    ) -> Result<(), SolveError> {
        self.setup(Self::rows_of(sym, values)?)
    }

    /// A symmetric matrix (structure `sym`, its `values` taken) in the row storage
    /// [`Self::setup`] takes: a caller can free the column structure before the set-up.
    pub fn rows_of(
        sym: SymbolicSparseColMatRef<'_, usize>,
        values: Vec<f64>,
    ) -> Result<Csr, SolveError> {
        super::check_finite_ref(SparseColMatRef::new(sym, &values))?;
        Ok(Csr::from_csc_values(sym, values))
    }

    /// [`Self::rows_of`] of a square matrix given as its CSC parts (column pointers,
    /// 32-bit rows ascending in each column, values), all taken: a structurally
    /// symmetric one becomes the rows with no copy.
    pub fn rows_of_parts(
        n: usize,
        col_ptr: Vec<usize>,
        rows: Vec<u32>,
        values: Vec<f64>,
    ) -> Result<Csr, SolveError> {
        for col in 0..n {
            for p in col_ptr[col]..col_ptr[col + 1] {
                if !values[p].is_finite() {
                    return Err(SolveError::NonFinite {
                        row: rows[p] as usize,
                        col,
                        value: values[p],
                    });
                }
            }
        }
        Ok(Csr::from_csc_parts(n, col_ptr, rows, values))
    }

    /// [`Self::rows_of_parts`] of a matrix known to be exactly symmetric, structure and
    /// values (as [`crate::assembly::Assembler::exactly_symmetric`] certifies): its
    /// columns are its rows as they are, so the pass that pairs each entry with its
    /// transpose (a random access per entry: 0.8 s at 31.7 M entries) is skipped. In
    /// debug builds the pairing is checked all the same.
    pub fn rows_of_symmetric_parts(
        n: usize,
        col_ptr: Vec<usize>,
        rows: Vec<u32>,
        values: Vec<f64>,
    ) -> Result<Csr, SolveError> {
        if cfg!(debug_assertions) {
            let a = Self::rows_of_parts(n, col_ptr.clone(), rows.clone(), values.clone())?;
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(
                a.ptr == col_ptr && a.idx == rows && bits(&a.val) == bits(&values),
                "the matrix handed over as exactly symmetric is not"
            );
        }
        if let Some(p) = values.iter().position(|v| !v.is_finite()) {
            let col = col_ptr.partition_point(|&q| q <= p) - 1;
            return Err(SolveError::NonFinite {
                row: rows[p] as usize,
                col,
                value: values[p],
            });
        }
        Ok(Csr {
            nrows: n,
            ncols: n,
            ptr: col_ptr,
            idx: rows,
            val: values,
        })
    }

    /// Build the hierarchy for a matrix in row storage.
    pub fn setup(&mut self, a: Csr) -> Result<(), SolveError> {
        self.levels.clear();
        self.reuse.set_up();
        self.earlier.clear();
        let mut a = a;
        let theta = self.options.strength;
        let mut inherited: Option<Vec<u32>> = None;
        loop {
            // The values the V-cycle will read, in single precision (module docs); the
            // estimate of ρ below reads them too (its products are the set-up's
            // costliest passes over the level). A finest level that will sweep with its
            // double-precision values (`fine_product`) has none made, and its estimate
            // reads those; should it stay the only level, they are made at the end.
            let fine = self.levels.is_empty();
            let a32: Vec<f32> = if fine && self.sweeps_make_product() {
                Vec::new()
            } else {
                a.val.iter().map(|&v| v as f32).collect()
            };
            let diag = a.diagonal();
            if let Some(row) = diag.iter().position(|&d| d <= 0.0 || !d.is_finite()) {
                return Err(SolveError::NotPositiveDefinite { row });
            }
            let inv_diag: Vec<f64> = diag.iter().map(|d| 1.0 / d).collect();
            // ω of the Jacobi smoother (10 products with A: not made for Gauss–Seidel).
            let omega = match self.options.smoother {
                Smoother::Jacobi => 4.0 / (3.0 * spectral_radius_dinv_a(&a, &inv_diag)),
                Smoother::SymmetricGaussSeidel => 0.0,
            };
            let n = a.nrows;
            let last =
                n <= self.options.coarse_size || self.levels.len() + 1 >= self.options.max_levels;
            // The rows of the penalty couplings and their neighbours. Where the rule
            // picks most of a level it has found no interface but positive couplings
            // all over: a Galerkin product's, on every row of some coarse levels (the
            // level sweeps the aggregates of the finer level's rows instead), or
            // stretched cells' on the fine level (a Q1 brick of aspect 5 couples its
            // in-plane face neighbours with +0.22 of the diagonal), where sweeping
            // every row again would make a second full sweep through the slower
            // row-list path: 2.3 times the CG time per iteration on the electronics
            // scene at 1.25 M unknowns for 17 iterations in place of 29 — none is
            // swept again there.
            let penalty_rows = if self.options.penalty_sweeps == 0 {
                Vec::new()
            } else {
                let rows = penalty_rows(&a, &diag);
                match inherited.take() {
                    Some(coarse_rows) if 2 * rows.len() > n => coarse_rows,
                    None if 2 * rows.len() > n => Vec::new(),
                    _ => rows,
                }
            };
            let mut coarse = None;
            if !last {
                let (agg, nagg) = aggregate(&a, theta);
                // Stop when aggregation stalls (nothing to coarsen, or too little).
                if nagg > 0 && (nagg as f64) < 0.8 * n as f64 {
                    let filtered = filtered_diagonal(&a);
                    let rho = if fine && self.options.fine_radius == FineRadius::Bound {
                        gershgorin_filtered(&a, &filtered)
                    } else if a32.is_empty() {
                        spectral_radius_filtered(a.with_values(&a.val), &filtered)
                    } else {
                        spectral_radius_filtered(a.with_values(&a32), &filtered)
                    };
                    let omega_p = 4.0 / (3.0 * rho);
                    let p = smoothed_prolongator(
                        &a,
                        &filtered,
                        &agg,
                        nagg,
                        omega_p,
                        self.options.truncation,
                    );
                    let r = p.transpose();
                    let ac = galerkin(&r, &a, &p);
                    coarse = Some((p, r, ac));
                    let mut rows: Vec<u32> = penalty_rows
                        .iter()
                        .map(|&i| agg[i as usize])
                        .filter(|&g| g != usize::MAX)
                        .map(|g| g as u32)
                        .collect();
                    rows.sort_unstable();
                    rows.dedup();
                    inherited = Some(rows);
                }
            }
            let blocks = if self.sweeps_make_product() {
                Blocks::new(&a, self.options.block_rows)
            } else {
                None
            };
            let (p, r, next) = match coarse {
                Some((p, r, ac)) => (p, r, Some(ac)),
                None => (Csr::default(), Csr::default(), None),
            };
            self.levels.push(Level {
                diag_at: a.diagonal_offsets(),
                a,
                inv_diag,
                omega,
                penalty_rows,
                p,
                r,
                a32,
                p32: Vec::new(),
                r32: Vec::new(),
                x: vec![0.0; n],
                b: vec![0.0; n],
                res: vec![0.0; n],
                saved: Vec::new(),
                blocks,
            });
            match next {
                Some(ac) => a = ac,
                None => break,
            }
        }
        if log::log_enabled!(log::Level::Debug) {
            let fine = self.levels[0].a.nnz().max(1) as f64;
            let all: usize = self.levels.iter().map(|l| l.a.nnz()).sum();
            let sizes: Vec<String> = self
                .levels
                .iter()
                .map(|l| {
                    let blocks = l.blocks.as_ref().map_or(String::new(), |b| {
                        format!(", {} blocks, {} rows across", b.count(), b.crossing_rows())
                    });
                    format!(
                        "{} ({} nnz, {} swept again{blocks})",
                        l.a.nrows,
                        l.a.nnz(),
                        l.penalty_rows.len()
                    )
                })
                .collect();
            log::debug!(
                "AMG hierarchy: {} levels, {}; operator complexity {:.2}",
                self.levels.len(),
                sizes.join(", "),
                all as f64 / fine
            );
        }
        let last = self.levels.last().unwrap();
        self.coarse_n = last.a.nrows;
        // Dense Cholesky costs n³/3 flops: fine to ~2000 unknowns (≈ 3e9 flops). A
        // larger coarsest level (coarsening stalled or `max_levels` reached) is
        // smoothed instead: 20 symmetric Gauss–Seidel sweeps.
        if self.coarse_n <= self.options.coarse_size.max(2000) {
            self.coarse = dense_cholesky(&last.a)?;
        } else {
            self.coarse.clear();
        }
        // The V-cycle's single-precision values of P and R; double precision stays
        // only where the operator itself is applied (the finest level: CG's A p).
        let single = |v: &[f64]| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
        if self.levels.len() > 1 && self.sweeps_make_product() {
            self.levels[0].a32 = Vec::new();
            self.product.resize(self.levels[0].a.nrows, 0.0);
        } else if self.levels[0].a32.is_empty() {
            let fine = &mut self.levels[0];
            fine.a32 = fine.a.val.iter().map(|&v| v as f32).collect();
        }
        for (l, lev) in self.levels.iter_mut().enumerate() {
            lev.p32 = single(&lev.p.val);
            lev.r32 = single(&lev.r.val);
            lev.p.val = Vec::new();
            lev.r.val = Vec::new();
            if l > 0 {
                lev.a.val = Vec::new();
            }
        }
        Ok(())
    }

    /// `y = A x` with the matrix of the last set-up.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        if let Some(level) = self.levels.first() {
            level.a.spmv(x, y);
        }
    }

    /// One V-cycle of the hierarchy set up last: `z ≈ A⁻¹ r` from a zero guess (a
    /// preconditioner for other Krylov methods).
    pub fn apply_vcycle(&mut self, r: &[f64], z: &mut [f64]) {
        self.fit_fine_values();
        self.precondition(r, z);
    }

    /// Apply one V-cycle to `r` (zero initial guess), giving `z ≈ A⁻¹ r`.
    fn precondition(&mut self, r: &[f64], z: &mut [f64]) {
        self.levels[0].b.copy_from_slice(r);
        self.vcycle(0);
        z.copy_from_slice(&self.levels[0].x);
    }

    fn vcycle(&mut self, l: usize) {
        let sweeps = self.options.sweeps;
        let smoother = self.options.smoother;
        // The cycle of one symmetric Gauss–Seidel sweep a side, the only one that
        // sweeps by blocks (the options are public: read them as they are now).
        let fused = self.sweeps_make_product();
        if l + 1 == self.levels.len() {
            let lev = &mut self.levels[l];
            if self.coarse.is_empty() {
                lev.x.fill(0.0);
                let a = lev.a.with_values(&lev.a32).with_diagonal(&lev.diag_at);
                for _ in 0..20 {
                    gauss_seidel(a, &lev.inv_diag, &mut lev.x, &lev.b, true);
                    gauss_seidel(a, &lev.inv_diag, &mut lev.x, &lev.b, false);
                }
            } else {
                lev.x.copy_from_slice(&lev.b);
                dense_cholesky_solve(&self.coarse, self.coarse_n, &mut lev.x);
            }
            return;
        }
        if fused {
            // The residual made in the sweeps' own passes (the matrix is symmetric).
            let penalty_sweeps = self.options.penalty_sweeps;
            let lev = &mut self.levels[l];
            lev.x.fill(0.0);
            let Level {
                a,
                a32,
                inv_diag,
                diag_at,
                penalty_rows,
                x,
                b,
                res,
                saved,
                blocks,
                ..
            } = lev;
            let parts = (inv_diag.as_slice(), penalty_rows.as_slice(), penalty_sweeps);
            let blocks = blocks.as_ref();
            if a32.is_empty() {
                let a = a.with_values(&a.val).with_diagonal(diag_at);
                presmooth_with_residual(a, parts, blocks, x, b, res, saved);
            } else {
                let a = a.with_values(a32).with_diagonal(diag_at);
                presmooth_with_residual(a, parts, blocks, x, b, res, saved);
            }
        } else {
            let lev = &mut self.levels[l];
            lev.x.fill(0.0);
            for k in 0..sweeps {
                if k == 0 && smoother == Smoother::SymmetricGaussSeidel {
                    let a = lev.a.with_values(&lev.a32).with_diagonal(&lev.diag_at);
                    gauss_seidel_from_zero(a, &lev.inv_diag, &mut lev.x, &lev.b);
                } else {
                    smooth(lev, smoother, true);
                }
            }
            lev.sweep_penalty_rows(self.options.penalty_sweeps);
            lev.a.with_values(&lev.a32).spmv(&lev.x, &mut lev.res);
            lev.res
                .par_iter_mut()
                .zip(&lev.b)
                .for_each(|(r, b)| *r = b - *r);
        }
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let r = fine[l].r.with_values(&fine[l].r32);
        r.spmv(&fine[l].res, &mut coarse[0].b);
        self.vcycle(l + 1);
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let lev = &mut fine[l];
        lev.p.with_values(&lev.p32).spmv(&coarse[0].x, &mut lev.res);
        lev.x
            .par_iter_mut()
            .zip(&lev.res)
            .for_each(|(x, c)| *x += c);
        lev.sweep_penalty_rows(self.options.penalty_sweeps);
        if lev.a32.is_empty() {
            // The finest level in double precision: its one backward sweep also makes
            // `A z` for CG (`fine_product`).
            let a = lev.a.with_values(&lev.a.val).with_diagonal(&lev.diag_at);
            let (x, b, y) = (&mut lev.x, &lev.b, &mut self.product);
            match lev.blocks.as_mut() {
                Some(blocks) => blocks.backward(a, &lev.inv_diag, x, b, Some(y)),
                None => gauss_seidel_backward_with_product(a, &lev.inv_diag, x, b, y),
            }
            return;
        }
        if fused && let Some(blocks) = lev.blocks.as_mut() {
            let a = lev.a.with_values(&lev.a32).with_diagonal(&lev.diag_at);
            blocks.backward(a, &lev.inv_diag, &mut lev.x, &lev.b, None);
            return;
        }
        for _ in 0..sweeps {
            smooth(lev, smoother, false);
        }
    }

    /// PCG on the finest level's matrix; `x` holds the initial guess and the result.
    pub fn pcg(&mut self, b: &[f64], x: &mut [f64]) -> Result<SolveReport, SolveError> {
        let mut r = vec![0.0; b.len()];
        self.levels[0].a.spmv(x, &mut r);
        r.par_iter_mut().zip(b).for_each(|(r, b)| *r = b - *r);
        self.pcg_from(b, x, r)
    }

    /// [`Self::pcg`] from `x` whose residual `b − A x` the caller has: `r`.
    fn pcg_from(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        r: Vec<f64>,
    ) -> Result<SolveReport, SolveError> {
        if !self.reuse.refreshed {
            return self.pcg_once(b, x, r);
        }
        // A refreshed hierarchy that fails is set up anew (for the same matrix) and the
        // solve made again from the same start (kept in spare vectors: a time step
        // would otherwise page in two fresh ones).
        let mut copy = |v: &[f64]| {
            let mut kept = self.spare.pop().unwrap_or_default();
            kept.clear();
            kept.extend_from_slice(v);
            kept
        };
        let (guess, start) = (copy(x), copy(&r));
        match self.pcg_once(b, x, r) {
            Err(SolveError::NotConverged { .. }) if self.set_up_again()? => {
                x.copy_from_slice(&guess);
                self.spare.push(guess);
                self.pcg_once(b, x, start)
            }
            other => {
                self.spare.extend([guess, start]);
                other
            }
        }
    }

    /// [`Self::pcg_from`] on the hierarchy as it is.
    fn pcg_once(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        mut r: Vec<f64>,
    ) -> Result<SolveReport, SolveError> {
        let n = b.len();
        let bnorm = norm(b);
        if bnorm == 0.0 {
            x.fill(0.0);
            return Ok(SolveReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        let mut vector = || {
            let mut v = self.spare.pop().unwrap_or_default();
            v.resize(n, 0.0);
            v
        };
        let (mut z, mut p, mut q) = (vector(), vector(), vector());
        let report = self.cg_loop(bnorm, x, &mut r, &mut z, &mut p, &mut q);
        self.spare.extend([r, z, p, q]);
        report
    }

    /// The iterations of [`Self::pcg_once`] in its vectors: `r` the residual at `x` on
    /// entry, `bnorm` the right-hand side's norm (nonzero); `z`, `p`, `q` of length n,
    /// their values overwritten.
    fn cg_loop(
        &mut self,
        bnorm: f64,
        x: &mut [f64],
        r: &mut [f64],
        z: &mut [f64],
        p: &mut [f64],
        q: &mut [f64],
    ) -> Result<SolveReport, SolveError> {
        let tol = self.options.tolerance;
        let mut rel = norm(r) / bnorm;
        // A start that meets the test already (a time step the earlier solutions
        // predict) needs no cycle.
        if rel <= tol {
            return Ok(SolveReport {
                iterations: 0,
                residual: rel,
            });
        }
        self.fit_fine_values();
        let fused = self.fine_product();
        self.precondition(r, z);
        p.copy_from_slice(z);
        if fused {
            q.copy_from_slice(&self.product);
        }
        let mut rz = dot(r, z);
        let mut it = 0;
        while rel > tol {
            if it == self.options.max_iterations {
                return Err(SolveError::NotConverged {
                    iterations: it,
                    residual: rel,
                    tolerance: tol,
                });
            }
            if !fused {
                self.levels[0].a.spmv(p, q);
            }
            let pq = dot(p, q);
            if pq <= 0.0 || !pq.is_finite() {
                return Err(SolveError::NotConverged {
                    iterations: it,
                    residual: rel,
                    tolerance: tol,
                });
            }
            let alpha = rz / pq;
            x.par_iter_mut().zip(&*p).for_each(|(x, p)| *x += alpha * p);
            r.par_iter_mut().zip(&*q).for_each(|(r, q)| *r -= alpha * q);
            rel = norm(r) / bnorm;
            it += 1;
            if rel <= tol {
                break;
            }
            self.precondition(r, z);
            let rz_new = dot(r, z);
            let beta = rz_new / rz;
            rz = rz_new;
            p.par_iter_mut()
                .zip(&*z)
                .for_each(|(p, z)| *p = z + beta * *p);
            if fused {
                // A p = A z + β A p_old: the product the last sweep made.
                q.par_iter_mut()
                    .zip(&self.product)
                    .for_each(|(q, az)| *q = az + beta * *q);
            }
        }
        Ok(SolveReport {
            iterations: it,
            residual: rel,
        })
    }
}

impl LinearSolver for AmgCg {
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        self.factor_ref(a.as_ref())
    }

    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError> {
        if self.levels.is_empty() {
            return Err(SolveError::NotFactored);
        }
        check_rhs(self.levels[0].a.nrows, b)?;
        let rhs = b.to_vec();
        b.fill(0.0);
        self.pcg(&rhs, b)
    }
}

/// The pre-smoothing of the symmetric cycle with one sweep: a forward sweep from zero
/// that leaves the residual in `res`, then the sweeps over the penalty rows keeping it
/// up to date. `parts`: the inverse diagonal, the penalty rows and their sweeps.
fn presmooth_with_residual<V: Copy + Into<f64> + Sync>(
    a: csr::Rows<'_, V>,
    (inv_diag, penalty_rows, penalty_sweeps): (&[f64], &[u32], usize),
    blocks: Option<&Blocks>,
    x: &mut [f64],
    b: &[f64],
    res: &mut [f64],
    saved: &mut Vec<f64>,
) {
    match blocks {
        Some(blocks) => blocks.forward_from_zero_with_residual(a, inv_diag, x, b, res),
        None => gauss_seidel_from_zero_with_residual(a, inv_diag, x, b, res),
    }
    for _ in 0..penalty_sweeps {
        symmetric_gauss_seidel_rows_with_residual(a, inv_diag, x, b, penalty_rows, res, saved);
    }
}

fn smooth(lev: &mut Level, smoother: Smoother, forward: bool) {
    match smoother {
        Smoother::SymmetricGaussSeidel => gauss_seidel(
            lev.a.with_values(&lev.a32),
            &lev.inv_diag,
            &mut lev.x,
            &lev.b,
            forward,
        ),
        Smoother::Jacobi => {
            lev.a.with_values(&lev.a32).spmv(&lev.x, &mut lev.res);
            let w = lev.omega;
            lev.x
                .par_iter_mut()
                .zip(&lev.res)
                .zip(&lev.b)
                .zip(&lev.inv_diag)
                .for_each(|(((x, ax), b), d)| *x += w * d * (b - ax));
        }
    }
}

/// Dense Cholesky of a small SPD matrix, row-major lower factor.
fn dense_cholesky(a: &Csr) -> Result<Vec<f64>, SolveError> {
    let n = a.nrows;
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for p in a.ptr[i]..a.ptr[i + 1] {
            l[i * n + a.idx[p] as usize] = a.val[p];
        }
    }
    for j in 0..n {
        let mut d = l[j * n + j];
        for k in 0..j {
            d -= l[j * n + k] * l[j * n + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return Err(SolveError::NotPositiveDefinite { row: j });
        }
        let d = d.sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let mut s = l[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = s / d;
        }
    }
    Ok(l)
}

fn dense_cholesky_solve(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= l[i * n + k] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
}

#[cfg(test)]
mod tests;
