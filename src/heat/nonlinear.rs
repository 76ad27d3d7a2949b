//! Conduction whose conductivity depends on temperature, assembled at an iterate for
//! Newton: each element's exact tangent into its matrix slot and its residual, negated,
//! into its load, so the assembled right-hand side is `−R(u)`. The terms are the
//! general solver's (`transient::assemble`): `∫ k(T) ∇N_a·∇T` and its Jacobian with the
//! `dk/dT` term, the face conditions' outflow `g(T)` and `dg/dT`, and a source of x.

use std::cell::Cell;

use crate::assembly::{Assembler, DofMap};
use crate::fem::{MAX_NODES, Measure};
use crate::mesh::Mesh;

use super::law::Law;
use super::{
    ByElement, FaceBc, FirstError, HeatError, SourceFn, bad_jacobian, block_rules, elem_coords,
    kernel, temperature,
};

/// Fill `asm`'s element slots with the conduction of `mesh` at the field `u` (over
/// `dofs`) at time `time`: the tangent `∂R/∂u` in the matrix slots, `−R` in the loads.
/// `conductivity[b]` is block `b`'s k(T, x, t); `sources[b]` its source (`None`: none);
/// `faces` the face conditions (flux, convection, radiation) on the mesh's sides.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub(crate) fn conduction_at(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    (conductivity, sources): (&[Law], &[Option<SourceFn<'_>>]),
    faces: &[FaceBc],
    (u, time): (&[f64], f64),
) -> Result<(), HeatError> {
    let blocks = mesh.blocks.len();
    if conductivity.len() != blocks {
        return Err(HeatError::MaterialCount {
            count: conductivity.len(),
            blocks,
        });
    }
    if sources.len() != blocks {
        return Err(HeatError::SourceCount {
            count: sources.len(),
            blocks,
        });
    }
    let k = |b: usize, temp: f64, x: [f64; 3]| conductivity[b].eval(temp, x, time);
    assemble_at(asm, mesh, dofs, (k, |b| sources[b]), faces, u)
}

/// [`conduction_at`] with block `b`'s conductivity `k(b, T, x)` (`Err`: a message for
/// the block) and source `source_of(b)`.
pub(super) fn assemble_at<'s>(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    (k_of, source_of): (
        impl Fn(usize, f64, [f64; 3]) -> Result<(f64, f64), String> + Sync,
        impl Fn(usize) -> Option<SourceFn<'s>> + Sync,
    ),
    faces: &[FaceBc],
    u: &[f64],
) -> Result<(), HeatError> {
    let field = temperature(dofs)?;
    let rules = block_rules(mesh, dofs, field)?;
    let measure = Measure::of(mesh.axisymmetric);
    let sides: Vec<_> = faces.iter().map(FaceBc::side).collect();
    let by_element = ByElement::new(mesh, &sides)?;
    let errors = FirstError::new();
    asm.elements(mesh, Some(dofs.field_blocks(field)), |e, ke, fe| {
        let b = mesh.block_of(e);
        let topo = mesh.blocks[b].topology;
        let rule = rules[b].as_ref().expect("rule of a temperature block");
        let mut x = [[0.0; 3]; MAX_NODES];
        let nn = elem_coords(mesh, e, &mut x);
        let x = &x[..nn];
        let mut elem_dofs = [0u32; MAX_NODES];
        dofs.first_field_dofs(mesh, e, &mut elem_dofs);
        let mut te = [0.0; MAX_NODES];
        for (t, &d) in te.iter_mut().zip(&elem_dofs[..nn]) {
            *t = u[d as usize];
        }
        let te = &te[..nn];
        let failed = Cell::new(None);
        let k = |temp: f64, xq: [f64; 3]| match k_of(b, temp, xq) {
            Ok(v) => v,
            Err(m) => {
                failed.set(Some(m));
                (0.0, 0.0)
            }
        };
        let mut re = [0.0; MAX_NODES];
        if let Err(bad) = kernel::conduction_residual_jacobian(rule, x, te, k, &mut re, ke) {
            errors.record(e, bad_jacobian(mesh, e, bad));
            return;
        }
        if let Some(message) = failed.take() {
            let block = mesh.blocks[b].id;
            errors.record(e, HeatError::Material { block, message });
            return;
        }
        for f in by_element.of(e) {
            let bc = faces[f];
            let outflow = |temp: f64, _: [f64; 3]| bc.outflow(temp);
            let side = bc.side().side;
            kernel::face_load_with(measure, topo, x, side, te, outflow, &mut re, ke);
        }
        // −R = ∫ Q N − (the rest), the source summed on its own first.
        let mut q_n = [0.0; MAX_NODES];
        if let Some(q) = source_of(b)
            && let Err(bad) = kernel::source(rule, x, q, &mut q_n)
        {
            errors.record(e, bad_jacobian(mesh, e, bad));
            return;
        }
        for ((f, q), r) in fe.iter_mut().zip(&q_n).zip(&re) {
            *f = q - r;
        }
    });
    errors.into_result()?;
    asm.check_finite(mesh)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Pattern;
    use crate::mesh::generate::{BoxSpec, single_box};

    /// The residual of the assembly at `u`, and its tangent applied to `v`.
    fn residual_and_tangent(
        mesh: &Mesh,
        dofs: &DofMap,
        law: &Law,
        faces: &[FaceBc],
        u: &[f64],
        v: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        let mut pattern = Pattern::new(mesh, dofs);
        pattern.build_direct().unwrap();
        let mut asm = Assembler::direct(&pattern).unwrap();
        let q = |x: [f64; 3]| 3.0 + x[0];
        let q: SourceFn<'_> = &q;
        let laws = vec![law.clone(); mesh.blocks.len()];
        let sources = vec![Some(q); mesh.blocks.len()];
        conduction_at(&mut asm, mesh, dofs, (&laws, &sources), faces, (u, 0.0)).unwrap();
        let r: Vec<f64> = asm.rhs().iter().map(|f| -f).collect();
        let j = asm.matrix().unwrap();
        let mut jv = vec![0.0; u.len()];
        crate::solve::spmv(&j, v, &mut jv);
        (r, jv)
    }

    /// The tangent is the residual's derivative: central differences of R along a
    /// direction agree with J v to 1e-7 relative, for a k(T) and a convection face, on
    /// distorted cells of a non-uniform field; with a constant k the residual is
    /// `K u − F` of the linear assembly.
    #[test]
    fn tangent_is_the_derivative_of_the_residual() {
        let mut mesh = single_box(BoxSpec::hex([0.0; 3], [1.0, 0.5, 0.7], [3, 2, 2], 1));
        for (i, x) in mesh.coords.iter_mut().enumerate() {
            x[0] += 0.03 * ((i * 7 % 5) as f64 - 2.0) * x[1] * (0.7 - x[2]);
        }
        let dofs = DofMap::new(&mesh, &[(super::super::TEMPERATURE, &[0])]).unwrap();
        let n = dofs.len();
        let u: Vec<f64> = (0..n)
            .map(|i| 300.0 + 40.0 * ((i * 13 % 17) as f64 / 17.0))
            .collect();
        let v: Vec<f64> = (0..n).map(|i| ((i * 5 % 11) as f64 / 11.0) - 0.4).collect();
        let law = Law::table(vec![(250.0, 2.0), (320.0, 3.5), (400.0, 1.0)]).unwrap();
        let side = crate::mesh::Side {
            elem: crate::mesh::ElemId(0),
            side: 1,
        };
        let faces = [FaceBc::Convection {
            side,
            h: 7.0,
            t_inf: 290.0,
        }];
        let (_, jv) = residual_and_tangent(&mesh, &dofs, &law, &faces, &u, &v);
        let eps = 1e-4;
        let shifted = |s: f64| -> Vec<f64> { u.iter().zip(&v).map(|(a, b)| a + s * b).collect() };
        let (rp, _) = residual_and_tangent(&mesh, &dofs, &law, &faces, &shifted(eps), &v);
        let (rm, _) = residual_and_tangent(&mesh, &dofs, &law, &faces, &shifted(-eps), &v);
        let scale = jv.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * eps);
            assert!(
                (fd - jv[i]).abs() <= 1e-7 * scale,
                "dof {i}: difference {fd}, tangent {}",
                jv[i]
            );
        }

        // A constant k: R = K u − F of the linear conduction assembly.
        let (r, _) = residual_and_tangent(&mesh, &dofs, &Law::Constant(2.5), &faces, &u, &v);
        let q = |x: [f64; 3]| 3.0 + x[0];
        let material = super::super::Material {
            conductivity: 2.5,
            rho_c: 1.0,
        };
        let system =
            super::super::steady_conduction(&mesh, &dofs, &[material], Some(&q), &[], &faces)
                .unwrap();
        let mut ku = vec![0.0; n];
        crate::solve::spmv(&system.matrix, &u, &mut ku);
        let scale = ku.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let linear = ku[i] - system.rhs[i];
            assert!(
                (linear - r[i]).abs() <= 1e-12 * scale,
                "dof {i}: {linear} vs {}",
                r[i]
            );
        }
    }
}
