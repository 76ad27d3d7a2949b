//! What a rank's own elements add to a distributed step besides the interfaces: their
//! linear conduction (its load made again where a source changes with time) and the
//! lumped capacity of a time step, ρc constant or of T (the serial general solver's
//! terms). The conduction of T at an iterate is [`crate::heat::nonlinear`]'s.

use crate::assembly::{Assembler, DofMap, Pattern};
use crate::heat::law::Law;
use crate::heat::steady::SteadyProblem;
use crate::heat::transient::LumpedWeight;
use crate::heat::{FaceBc, HeatError, assemble_conduction_by_block};
use crate::mesh::{ElemId, Mesh};

use super::rows::local_faces;

/// The capacity terms of a time step (lumped, as the serial general solver's):
/// `m (c₀ u + rest)` in the residual, `c₀ m` on the Jacobian's diagonal; with a ρc of T,
/// `Σ w ρc(u) (c₀ u + rest)` and its derivative.
pub(super) struct Capacity<'a> {
    /// Per local dof, the lumped capacity `∫ ρc N_a` of this rank's own elements (0 at
    /// the dofs none of them holds).
    pub m: &'a [f64],
    /// `α₀/Δt`.
    pub c0: f64,
    /// Per local dof, `(α₁ uⁿ + α₂ uⁿ⁻¹)/Δt`.
    pub rest: &'a [f64],
    /// A ρc of T: the lumped weights `∫ N_a` of this rank's own elements per (dof,
    /// block), ρc per block, and the step's time (`m` is then not read).
    pub of_t: Option<(&'a [LumpedWeight], &'a [Law], f64)>,
}

impl Capacity<'_> {
    /// Per local dof, the capacity's residual and its Jacobian's diagonal at `u`, at the
    /// dofs `touched` (the rank's elements'); a ρc that fails is the step's error.
    pub(super) fn terms(
        &self,
        u: &[f64],
        touched: &[usize],
    ) -> Result<(Vec<f64>, Vec<f64>), HeatError> {
        let (mut r, mut diagonal) = (vec![0.0; u.len()], vec![0.0; u.len()]);
        let Some((weights, laws, t)) = self.of_t else {
            for &d in touched {
                r[d] = self.m[d] * (self.c0 * u[d] + self.rest[d]);
                diagonal[d] = self.c0 * self.m[d];
            }
            return Ok((r, diagonal));
        };
        for &(d, b, w, x) in weights {
            let d = d as usize;
            let (c, dc) = laws[b as usize].eval(u[d], x, t).map_err(HeatError::Step)?;
            let rate = self.c0 * u[d] + self.rest[d];
            r[d] += w * c * rate;
            diagonal[d] += w * (c * self.c0 + dc * rate);
        }
        Ok((r, diagonal))
    }
}

/// What a linear conduction is made of: the pattern of a rank's elements, the face
/// conditions (of the problem's mesh), and the sources as laws taken at time `t` where
/// they change with time (else the problem's own, of x).
pub(super) struct Conduction<'a> {
    pub pattern: &'a Pattern,
    pub faces: &'a [FaceBc],
    pub sources: Option<&'a [Law]>,
    pub t: f64,
}

/// The conduction of the `local` mesh's elements (this rank's own; per element of the
/// problem's mesh its element there) with `terms`: values and load.
pub(super) fn conduction<'a>(
    p: &SteadyProblem<'_>,
    (local, to_local): (&Mesh, &[Option<ElemId>]),
    dofs: &DofMap,
    terms: Conduction<'a>,
) -> Result<(Vec<f64>, Vec<f64>), HeatError> {
    let faces = local_faces(terms.faces, to_local);
    let mut asm = Assembler::direct(terms.pattern)?;
    match terms.sources {
        None => p.conduction_with_faces(&mut asm, local, dofs, &faces)?,
        Some(laws) => {
            // Each source at time t (of x alone: the linear conduction's); the first
            // failure met is reported.
            let mutex = std::sync::Mutex::new(None::<String>);
            let failed = &mutex;
            let closures: Vec<_> = (laws.iter())
                .map(|law: &'a Law| law.source_of_x(terms.t, failed))
                .collect();
            let sources: Vec<Option<crate::heat::SourceFn<'_>>> = (closures.iter())
                .zip(laws)
                .map(|(f, law)| (*law != Law::Constant(0.0)).then_some(f as _))
                .collect();
            let m = p.materials;
            assemble_conduction_by_block(&mut asm, local, dofs, m, &sources, &faces)?;
            drop(sources);
            drop(closures);
            if let Some(m) = mutex.into_inner().unwrap_or_else(|e| e.into_inner()) {
                return Err(HeatError::Step(format!("[[source]]: {m}")));
            }
        }
    }
    let f = asm.rhs();
    let k = asm.take_values()?;
    Ok((k, f))
}
