//! Conduction whose terms depend on temperature, assembled at an iterate for Newton:
//! each element's exact tangent into its matrix slot and its residual, negated, into
//! its load, so the assembled right-hand side is `−R(u)`. The terms are the general
//! solver's (`transient::assemble`): `∫ k(T) ∇N_a·∇T` and its Jacobian with the `dk/dT`
//! term, the face conditions' outflow `g(T)` (flux, convection, radiation) and `dg/dT`,
//! and the source `−∫ Q(T, x, t) N_a` with its `dQ/dT`.

use std::cell::Cell;

use crate::assembly::{Assembler, DofMap};
use crate::fem::{Basis, MAX_NODES, Measure};
use crate::mesh::Mesh;

use super::law::Law;
use super::{
    ByElement, FaceBc, FirstError, HeatError, bad_jacobian, block_rules, elem_coords, kernel,
    temperature,
};

/// Fill `asm`'s element slots with the conduction of `mesh` at the field `u` (over
/// `dofs`) at time `time`: the tangent `∂R/∂u` in the matrix slots, `−R` in the loads.
/// `conductivity[b]` is block `b`'s k(T, x, t), `source[b]` its Q(T, x, t) (a constant 0:
/// none); `faces` the face conditions on the mesh's sides.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub(crate) fn conduction_at(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    (conductivity, source): (&[Law], &[Law]),
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
    if source.len() != blocks {
        return Err(HeatError::SourceCount {
            count: source.len(),
            blocks,
        });
    }
    let k = |b: usize, temp: f64, x: [f64; 3]| conductivity[b].eval(temp, x, time);
    // Q(T, x, t) and dQ/dT into the residual and the tangent; a failure or a value that
    // is not finite is the block's error there (the serial general solver's message).
    let q = |b: usize, rule: &Basis, x: &[[f64; 3]], te: &[f64], re: &mut [f64], ke: &mut [f64]| {
        if source[b] == Law::Constant(0.0) {
            return Ok(());
        }
        let failed = Cell::new(None);
        let q = |temp: f64, xq: [f64; 3]| {
            source[b].source_at(temp, xq, time).unwrap_or_else(|m| {
                failed.set(Some(m));
                (0.0, 0.0)
            })
        };
        kernel::source_residual_jacobian(rule, x, te, q, re, ke)
            .map_err(ElementFailure::Jacobian)?;
        failed
            .take()
            .map_or(Ok(()), |m| Err(ElementFailure::Source(m)))
    };
    assemble_at(asm, mesh, dofs, (k, q), faces, u)
}

/// Why an element's source could not be added.
pub(super) enum ElementFailure {
    Jacobian(crate::fem::BadJacobian),
    /// A source that failed or was not finite, with where.
    Source(String),
}

/// [`conduction_at`] with block `b`'s conductivity `k(b, T, x)` (`Err`: a message for
/// the block) and its source added by `source(b, rule, x, T_e, R_e, J_e)`.
pub(super) fn assemble_at(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    (k_of, source): (
        impl Fn(usize, f64, [f64; 3]) -> Result<(f64, f64), String> + Sync,
        impl Fn(
            usize,
            &Basis,
            &[[f64; 3]],
            &[f64],
            &mut [f64],
            &mut [f64],
        ) -> Result<(), ElementFailure>
        + Sync,
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
        let re = &mut re[..nn];
        if let Err(bad) = kernel::conduction_residual_jacobian(rule, x, te, k, re, ke) {
            errors.record(e, bad_jacobian(mesh, e, bad));
            return;
        }
        let block = mesh.blocks[b].id;
        if let Some(message) = failed.take() {
            errors.record(e, HeatError::Material { block, message });
            return;
        }
        for f in by_element.of(e) {
            let bc = faces[f];
            let outflow = |temp: f64, _: [f64; 3]| bc.outflow(temp);
            let side = bc.side().side;
            kernel::face_load_with(measure, topo, x, side, te, outflow, re, ke);
        }
        match source(b, rule, x, te, re, ke) {
            Ok(()) => {}
            Err(ElementFailure::Jacobian(bad)) => {
                return errors.record(e, bad_jacobian(mesh, e, bad));
            }
            Err(ElementFailure::Source(message)) => {
                return errors.record(e, HeatError::Source { block, message });
            }
        }
        for (f, r) in fe.iter_mut().zip(re.iter()) {
            *f = -r;
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

    /// The source `expr` as a law.
    fn lua(expr: &str) -> Law {
        Law::Lua {
            expr: expr.into(),
            chunk: "source".into(),
        }
    }

    /// The residual of the assembly at `u` with the conductivity `law` and the source
    /// `q`, and its tangent applied to `v`.
    fn residual_and_tangent(
        mesh: &Mesh,
        dofs: &DofMap,
        (law, q): (&Law, &Law),
        faces: &[FaceBc],
        u: &[f64],
        v: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        let mut pattern = Pattern::new(mesh, dofs);
        pattern.build_direct().unwrap();
        let mut asm = Assembler::direct(&pattern).unwrap();
        let laws = vec![law.clone(); mesh.blocks.len()];
        let sources = vec![q.clone(); mesh.blocks.len()];
        conduction_at(&mut asm, mesh, dofs, (&laws, &sources), faces, (u, 0.0)).unwrap();
        let r: Vec<f64> = asm.rhs().iter().map(|f| -f).collect();
        let j = asm.matrix().unwrap();
        let mut jv = vec![0.0; u.len()];
        crate::solve::spmv(&j, v, &mut jv);
        (r, jv)
    }

    /// The tangent is the residual's derivative: central differences of R along a
    /// direction agree with J v to 1e-7 relative, for a k(T), a Q(T), a convection and a
    /// radiating face, on
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
        let radiating = crate::mesh::Side {
            elem: crate::mesh::ElemId(3),
            side: 2,
        };
        let faces = [
            FaceBc::Convection {
                side,
                h: 7.0,
                t_inf: 290.0,
            },
            FaceBc::Radiation {
                side: radiating,
                emissivity: 0.7,
                t_inf: 500.0,
            },
        ];
        // Q = 3 + x + T/100: its dQ/dT in the tangent too.
        let q = lua("3 + x + T/100");
        let terms = (&law, &q);
        let (_, jv) = residual_and_tangent(&mesh, &dofs, terms, &faces, &u, &v);
        let eps = 1e-4;
        let shifted = |s: f64| -> Vec<f64> { u.iter().zip(&v).map(|(a, b)| a + s * b).collect() };
        let (rp, _) = residual_and_tangent(&mesh, &dofs, terms, &faces, &shifted(eps), &v);
        let (rm, _) = residual_and_tangent(&mesh, &dofs, terms, &faces, &shifted(-eps), &v);
        let scale = jv.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * eps);
            assert!(
                (fd - jv[i]).abs() <= 1e-7 * scale,
                "dof {i}: difference {fd}, tangent {}",
                jv[i]
            );
        }

        // A constant k, no radiation: R = K u − F of the linear conduction assembly.
        let (terms, faces) = ((&Law::Constant(2.5), &lua("3 + x")), &faces[..1]);
        let (r, _) = residual_and_tangent(&mesh, &dofs, terms, faces, &u, &v);
        let q = |x: [f64; 3]| 3.0 + x[0];
        let material = super::super::Material {
            conductivity: 2.5,
            rho_c: 1.0,
        };
        let system =
            super::super::steady_conduction(&mesh, &dofs, &[material], Some(&q), &[], faces)
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
