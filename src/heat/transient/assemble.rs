//! The residual and Jacobian of a step at `u` (elements, faces, sources, capacity,
//! interface forms and mortar ties) and the heat through each interface.

use std::cell::Cell;

use rayon::prelude::*;

use crate::assembly::Assembler;
use crate::fem::{MAX_NODES, Measure};
use crate::heat::electric;
use crate::heat::interfaces::InterfaceFailure;
use crate::heat::kernel;
use crate::heat::law::Law;
use crate::heat::{ByElement, FirstError, HeatError, bad_jacobian, elem_coords};
use crate::slices::same_bits;

use super::newton::{Context, History};
use super::{Failure, Loads};

/// Heat leaving side A and side B of one interface, W.
pub(super) type Heat = (f64, f64);

impl Context<'_, '_> {
    /// Residual and Jacobian (left in `asm`) at `u`, and the heat of each flux term.
    pub(super) fn assemble(
        &self,
        asm: &mut Assembler<'_>,
        u: &[f64],
        t: f64,
        loads: &Loads,
        history: Option<&History<'_>>,
        linear: bool,
    ) -> Result<(Vec<f64>, Vec<Heat>), Failure> {
        let p = self.p;
        let setup = self.setup;
        let mesh = p.mesh;
        let dofs = &setup.dofs;
        let (blocks, rules) = (&setup.blocks, &setup.rules);
        let by_element =
            |sides: Vec<crate::mesh::Side>| ByElement::new(mesh, &sides).map_err(Failure::Fatal);
        let faces = by_element(loads.faces.iter().map(|f| f.side()).collect())?;
        let currents = by_element(loads.currents.iter().map(|(s, _)| *s).collect())?;
        let species_fluxes = by_element(loads.species_fluxes.iter().map(|(s, _)| *s).collect())?;
        let errors = FirstError::new();
        let (laws, source, block_source) = (p.laws, p.source, p.block_source);
        let sigmas = p.electric.as_ref().map(|el| el.conductivity);
        let cx = ElementCx {
            mesh,
            laws,
            block_source,
            setup,
            u,
            t,
            loads,
            faces: &faces,
            currents: &currents,
            species_fluxes: &species_fluxes,
        };
        // A linear problem's element matrices (conduction, and the faces' dg/dT) stay
        // the same while the face conditions' derivatives do: then they are kept in
        // their slots and only the vectors are computed. Either way a linear element's
        // residual is `K_e T_e + g(0) − f`, so keeping or recomputing gives the same bits.
        let signature: Option<Vec<(u32, u8, f64)>> = linear.then(|| {
            loads
                .faces
                .iter()
                .map(|f| (f.side().elem.0, f.side().side, f.outflow(0.0).1))
                .collect()
        });
        // Element death changes the matrices: the count of dead elements is part of the
        // signature.
        self.refresh_alive(t)?;
        let signature = signature.map(|mut s| {
            let dead = self.alive.borrow().as_ref().map_or(0, |a| a.dead);
            s.push((u32::MAX, 0, dead as f64));
            s
        });
        // A species block's element matrix holds the thermal one inside a wider one: it
        // is computed each time (no kept matrices with a species).
        let diffusivity = p.species.as_ref().map(|s| s.diffusivity);
        let keep = diffusivity.is_none()
            && signature.is_some()
            && *self.element_matrices.borrow() == signature;
        let death = p.death;
        // Blocks with a heat source: a block's own law unless it is a constant 0, else
        // the problem's source.
        let sourced: Vec<bool> = (0..mesh.blocks.len())
            .map(|b| match (block_source, source) {
                (Some(qb), _) => !matches!(qb[b], Law::Constant(v) if v == 0.0),
                (None, source) => source.is_some(),
            })
            .collect();
        let thermal = |e: crate::mesh::ElemId, je: &mut [f64], re: &mut [f64]| {
            let b = mesh.block_of(e);
            if let Some(sigma) = sigmas.and_then(|s| s.get(b)?.as_ref()) {
                if let Err(err) = cx.electric_element(e, sigma, re, je) {
                    errors.record(e, err);
                }
                return;
            }
            let topo = mesh.blocks[b].topology;
            let rule = rules[b].as_ref().expect("rule of a field block");
            let mut elem_dofs = [0u32; MAX_NODES];
            let nn = dofs.first_field_dofs(mesh, e, &mut elem_dofs);
            let mut te = [0.0; MAX_NODES];
            for (k, d) in elem_dofs.iter().take(nn).enumerate() {
                te[k] = u[*d as usize];
            }
            let at_zero = te[..nn].iter().all(|&v| v == 0.0);
            // Kept matrices at a zero field (see `from_zero` in the Newton step), with
            // no face condition and no source: the element adds nothing.
            if keep && at_zero && !sourced[b] && faces.of(e).next().is_none() {
                return;
            }
            let mut x = [[0.0; 3]; MAX_NODES];
            elem_coords(mesh, e, &mut x);
            // Linear: the matrix at T = 0, then the residual from it.
            let t_eval = if linear { [0.0; MAX_NODES] } else { te };
            let law = &laws[b].conductivity;
            let failed = Cell::new(None);
            let k = |temp: f64, xq: [f64; 3]| match law.eval(temp, xq, t) {
                Ok(v) => v,
                Err(m) => {
                    failed.set(Some(m));
                    (0.0, 0.0)
                }
            };
            // Q(T, x, t) and dQ/dT; a failure or a non-finite value stops the run there.
            let q_failed = Cell::new(None);
            let q = |temp: f64, xq: [f64; 3]| {
                let v = block_source.map_or(Ok((0.0, 0.0)), |s| s[b].source_at(temp, xq, t));
                v.unwrap_or_else(|m| {
                    q_failed.set(Some(m));
                    (0.0, 0.0)
                })
            };
            let conduction = if keep {
                Ok(())
            } else {
                kernel::conduction_residual_jacobian(rule, &x[..nn], &t_eval[..nn], k, re, je)
            };
            if let Err(bad) = conduction {
                errors.record(e, bad_jacobian(mesh, e, bad));
                return;
            }
            if let Some(m) = failed.take() {
                errors.record(
                    e,
                    HeatError::Material {
                        block: mesh.blocks[b].id,
                        message: m,
                    },
                );
                return;
            }
            let mut scratch = [0.0; MAX_NODES * MAX_NODES];
            for k in faces.of(e) {
                let bc = loads.faces[k];
                // Kept matrices hold the faces' dg/dT already.
                let jf = if keep {
                    &mut scratch[..nn * nn]
                } else {
                    &mut *je
                };
                kernel::face_load_with(
                    Measure::of(mesh.axisymmetric),
                    topo,
                    &x[..nn],
                    bc.side().side,
                    &t_eval[..nn],
                    |temp, _| bc.outflow(temp),
                    re,
                    jf,
                );
            }
            // (An element at zero reads no matrix: see `from_zero` in the Newton step.)
            if linear && !at_zero {
                for a in 0..nn {
                    re[a] += (0..nn).map(|c| je[a * nn + c] * te[c]).sum::<f64>();
                }
            }
            // Sources at the element's temperatures (a linear problem's do not depend on
            // T, so their dQ/dT adds nothing to the kept matrices).
            let mut f = [0.0; MAX_NODES];
            let mut scratch = [0.0; MAX_NODES * MAX_NODES];
            let sourced = match (block_source, source) {
                (Some(_), _) if sourced[b] => {
                    let js = if keep {
                        &mut scratch[..nn * nn]
                    } else {
                        &mut *je
                    };
                    kernel::source_residual_jacobian(rule, &x[..nn], &te[..nn], q, re, js)
                }
                (None, Some(q)) => kernel::source(rule, &x[..nn], q, &mut f),
                _ => Ok(()),
            };
            if let Err(bad) = sourced {
                errors.record(e, bad_jacobian(mesh, e, bad));
                return;
            }
            if let Some(message) = q_failed.take() {
                let block = mesh.blocks[b].id;
                errors.record(e, HeatError::Source { block, message });
                return;
            }
            re.iter_mut().zip(&f).for_each(|(r, f)| *r -= f);
        };
        // With kept matrices the element loop makes only the element vectors, from the
        // field, the face conditions, the sources and the time. Asked again with the same
        // (a linear step with fixed steps assembles at the same u₀ every step), the
        // assembler holds its vectors already.
        let timeless =
            death.is_none() && block_source.is_none_or(|s| s.iter().all(|q| !q.depends_on_time()));
        let repeated = keep
            && (self.element_inputs.borrow().as_ref())
                .is_some_and(|last| last.same_as(u, t, loads, timeless));
        if !repeated {
            asm.elements_with(mesh, Some(blocks), keep, |e, je, re| {
                if super::death::is_dead(death, e, t) {
                    return;
                }
                let d = diffusivity.and_then(|d| d.get(mesh.block_of(e))?.as_ref());
                match d {
                    Some(d) => {
                        if let Err(err) = cx.species_element(e, d, &thermal, re, je) {
                            errors.record(e, err);
                        }
                    }
                    None => thermal(e, je, re),
                }
            });
        }
        let failed = errors.into_result();
        if !repeated {
            *self.element_inputs.borrow_mut() =
                (keep && failed.is_ok()).then(|| ElementInputs::of(u, t, loads));
        }
        failed?;
        if !keep {
            asm.check_finite(mesh).map_err(HeatError::from)?;
        }
        *self.element_matrices.borrow_mut() = signature;
        asm.reset_couplings();
        let mut r = asm.rhs();
        // Capacity (lumped): M(u)(α₀u + α₁uⁿ + α₂uⁿ⁻¹)/Δt on the diagonal.
        let alive = self.alive.borrow();
        // The species has its own capacity, φ per block.
        let species = setup.species.map(|c| setup.dofs.field_range(c));
        let phi = p.species.as_ref().map(|s| s.capacity);
        if let Some(h) = history {
            let lumped = alive.as_ref().map_or(&setup.lumped, |a| &a.lumped);
            // Each dof's (residual, diagonal) terms in a buffer kept from step to step
            // (40 MB of fresh pages each step at 1.25 M unknowns otherwise); the first
            // failure in dof order is the one reported.
            let mut terms = self.capacity_terms.borrow_mut();
            terms.resize(lumped.len(), (0.0, 0.0));
            let failed: std::sync::Mutex<Option<(usize, String)>> = Default::default();
            terms
                .par_iter_mut()
                .zip(lumped.par_iter())
                .enumerate()
                .with_min_len(4096)
                .for_each(|(k, (term, &(d, b, w, xn)))| {
                    let d = d as usize;
                    let (c, dc) = match (&species, phi) {
                        (Some(r), Some(phi)) if r.contains(&d) => (phi[b as usize], 0.0),
                        _ => match p.laws[b as usize].capacity.eval(u[d], xn, t) {
                            Ok(v) => v,
                            Err(m) => {
                                let mut f = failed.lock().unwrap_or_else(|e| e.into_inner());
                                if f.as_ref().is_none_or(|(j, _)| k < *j) {
                                    *f = Some((k, m));
                                }
                                return;
                            }
                        },
                    };
                    let mut rate = h.alpha[0] * u[d] + h.alpha[1] * h.current[d];
                    if let Some(prev) = h.previous {
                        rate += h.alpha[2] * prev[d];
                    }
                    rate /= h.dt;
                    *term = (w * c * rate, w * (c * h.alpha[0] / h.dt + dc * rate));
                });
            if let Some((_, m)) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
                return Err(Failure::Fatal(HeatError::Step(m)));
            }
            for (&(rv, jv), &(d, ..)) in terms.iter().zip(lumped) {
                r[d as usize] += rv;
                asm.add_diagonal(d as usize, jv);
            }
        }
        // The dofs no live element holds keep their value: u − uⁿ = 0 (a steady
        // solve keeps u).
        if let Some(a) = alive.as_ref() {
            for &d in &a.orphans {
                r[d] = history.map_or(0.0, |h| u[d] - h.current[d]);
                asm.add_diagonal(d, 1.0);
            }
        }
        drop(alive);
        // Interfaces.
        let heat = match p.interfaces {
            Some(i) => i
                .assemble(u, t, &mut r, asm, self.first)
                .map_err(|e| match e {
                    InterfaceFailure::Cutback(m) => Failure::Retry(format!(
                        "a conductance model asked for a smaller step ({m})"
                    )),
                    InterfaceFailure::Failed(m) => Failure::Fatal(HeatError::Contact(m)),
                })?,
            None => Vec::new(),
        };
        // Electrical contacts: the voltage interface and its Joule heat.
        if let Some(el) = &p.electric {
            let contacts = setup.electric();
            let mut power = Vec::with_capacity(contacts.len());
            for ((c, (_, h)), &first) in contacts.iter().zip(&el.contacts).zip(self.electric_first)
            {
                let at_t = |i: &crate::enforce::interface::HInput| h(i, t);
                let pw = c
                    .assemble(u, &at_t, &mut r, asm, first)
                    .map_err(|m| Failure::Fatal(HeatError::Contact(m)))?;
                power.push(pw);
            }
            *self.power.borrow_mut() = power;
        }
        // Ties: Cᵀλ and C u − ΔT ∫ψ; a tie switched off keeps λ = 0.
        for (ti, tie) in setup.ties.iter().enumerate() {
            let l0 = setup.lambda_first[ti];
            if !p.tie_on(ti, t) {
                for k in 0..tie.own.len() {
                    r[l0 + k] = u[l0 + k];
                    asm.add_diagonal(l0 + k, 1.0);
                }
                continue;
            }
            for (e, &(k, d, c)) in tie.entries.iter().enumerate() {
                let l = l0 + k;
                r[d] += c * u[l];
                r[l] += c * u[d];
                asm.add_coupling(self.tie_first[ti] + e, c, c);
            }
            for (k, g) in tie.rhs.iter().enumerate() {
                r[l0 + k] -= g;
            }
        }
        Ok((r, heat))
    }

    /// Heat through each interface at `u`: the flux terms' `flux` (from the last
    /// assembly at `u`), then the ties' from Cᵀλ.
    pub(super) fn heat(&self, flux: Vec<Heat>, u: &[f64]) -> Vec<Heat> {
        let mut out = flux;
        for (ti, tie) in self.setup.ties.iter().enumerate() {
            let l0 = self.setup.lambda_first[ti];
            out.push(tie.heat(&u[l0..l0 + tie.own.len()]));
        }
        out
    }
}

/// What an element loop over kept element matrices reads besides them: the field, the
/// time and the step's face conditions, currents and species fluxes.
pub(super) struct ElementInputs {
    u: Vec<f64>,
    t: f64,
    faces: Vec<crate::heat::FaceBc>,
    currents: Vec<(crate::mesh::Side, f64)>,
    species_fluxes: Vec<(crate::mesh::Side, f64)>,
}

impl ElementInputs {
    fn of(u: &[f64], t: f64, loads: &Loads) -> ElementInputs {
        ElementInputs {
            u: u.to_vec(),
            t,
            faces: loads.faces.clone(),
            currents: loads.currents.clone(),
            species_fluxes: loads.species_fluxes.clone(),
        }
    }

    /// Whether a loop reading `u`, `t` and `loads` makes the vectors this one made: the
    /// same field (bit for bit), conditions and fluxes, and the same time unless nothing
    /// read depends on it (`timeless`).
    fn same_as(&self, u: &[f64], t: f64, loads: &Loads, timeless: bool) -> bool {
        (self.t == t || timeless)
            && self.faces == loads.faces
            && self.currents == loads.currents
            && self.species_fluxes == loads.species_fluxes
            && same_bits(&self.u, u)
    }
}

/// An element kernel: `(element, matrix, vector)`, as [`Assembler::elements_with`] calls it.
type ElementKernel<'k> = dyn Fn(crate::mesh::ElemId, &mut [f64], &mut [f64]) + Sync + 'k;

/// What an element of a block with a voltage needs (shared by the element threads).
struct ElementCx<'c> {
    mesh: &'c crate::mesh::Mesh,
    laws: &'c [super::BlockLaws],
    block_source: Option<&'c [Law]>,
    setup: &'c super::setup::Setup,
    u: &'c [f64],
    t: f64,
    loads: &'c Loads,
    /// The face conditions, currents and species fluxes of each element.
    faces: &'c ByElement,
    currents: &'c ByElement,
    species_fluxes: &'c ByElement,
}

impl ElementCx<'_> {
    /// One element of a block with a voltage: the coupled conduction, Joule heat and
    /// charge kernel, its face conditions on the temperature (flux, convection,
    /// radiation) and on the voltage (currents), and its block's heat source.
    fn electric_element(
        &self,
        e: crate::mesh::ElemId,
        sigma: &Law,
        re: &mut [f64],
        je: &mut [f64],
    ) -> Result<(), HeatError> {
        let (setup, mesh, u, t, loads) = (self.setup, self.mesh, self.u, self.t, self.loads);
        let (faces, currents) = (self.faces, self.currents);
        let b = mesh.block_of(e);
        let topo = mesh.blocks[b].topology;
        let rule = setup.rules[b].as_ref().expect("rule of a field block");
        let mut x = [[0.0; 3]; MAX_NODES];
        let nn = elem_coords(mesh, e, &mut x);
        let mut elem_dofs = Vec::with_capacity(2 * nn);
        setup.dofs.elem_dofs(mesh, e, &mut elem_dofs);
        let mut te = [0.0; MAX_NODES];
        let mut ve = [0.0; MAX_NODES];
        for k in 0..nn {
            te[k] = u[elem_dofs[k] as usize];
            ve[k] = u[elem_dofs[nn + k] as usize];
        }
        let block = mesh.blocks[b].id;
        let failed = Cell::new(None);
        let k = checked(&self.laws[b].conductivity, "conductivity", t, &failed);
        let s = checked(sigma, "electrical conductivity", t, &failed);
        electric::joule_residual_jacobian(rule, &x[..nn], &te[..nn], &ve[..nn], (k, s), re, je)
            .map_err(|bad| bad_jacobian(mesh, e, bad))?;
        if let Some(message) = failed.take() {
            return Err(HeatError::Material { block, message });
        }
        // The currents fed in: R_V,a −= ∫ j N_a dA (no Jacobian).
        for k in currents.of(e) {
            let (side, j) = loads.currents[k];
            influx(mesh, topo, &x[..nn], side.side, j, &mut re[nn..2 * nn]);
        }
        // The temperature and voltage blocks of the element matrix, nn × nn each.
        let w = 2 * nn;
        let mut add = |off: usize, rs: &[f64], js: &[f64]| {
            for a in 0..nn {
                re[off + a] += rs[a];
                for c in 0..nn {
                    je[(off + a) * w + off + c] += js[a * nn + c];
                }
            }
        };
        let mut rs = [0.0; MAX_NODES];
        let mut js = [0.0; MAX_NODES * MAX_NODES];
        for k in faces.of(e) {
            let bc = loads.faces[k];
            let (rs, js) = (&mut rs[..nn], &mut js[..nn * nn]);
            rs.fill(0.0);
            js.fill(0.0);
            kernel::face_load_with(
                Measure::of(mesh.axisymmetric),
                topo,
                &x[..nn],
                bc.side().side,
                &te[..nn],
                |temp, _| bc.outflow(temp),
                rs,
                js,
            );
            add(0, rs, js);
        }
        if let Some(qb) = self.block_source {
            let q_failed = Cell::new(None);
            let q = |temp: f64, xq: [f64; 3]| match qb[b].eval(temp, xq, t) {
                Ok(v) => v,
                Err(m) => {
                    q_failed.set(Some(m));
                    (0.0, 0.0)
                }
            };
            let (rs, js) = (&mut rs[..nn], &mut js[..nn * nn]);
            rs.fill(0.0);
            js.fill(0.0);
            kernel::source_residual_jacobian(rule, &x[..nn], &te[..nn], q, rs, js)
                .map_err(|bad| bad_jacobian(mesh, e, bad))?;
            if let Some(message) = q_failed.take() {
                return Err(HeatError::Source { block, message });
            }
            add(0, rs, js);
        }
        Ok(())
    }
}

impl ElementCx<'_> {
    /// One element of a block with a species: its thermal (or thermal–electrical) part
    /// by `thermal` into the leading rows and columns, then the concentration's rows
    /// (diffusion with D(T) and its T-derivative, the species fluxes into its faces) at
    /// the end of the element's dofs ([`crate::heat::species`]).
    fn species_element(
        &self,
        e: crate::mesh::ElemId,
        diffusivity: &Law,
        thermal: &ElementKernel<'_>,
        re: &mut [f64],
        je: &mut [f64],
    ) -> Result<(), HeatError> {
        let (setup, mesh, u, t, loads) = (self.setup, self.mesh, self.u, self.t, self.loads);
        let b = mesh.block_of(e);
        let topo = mesh.blocks[b].topology;
        let rule = setup.rules[b].as_ref().expect("rule of a field block");
        let mut x = [[0.0; 3]; MAX_NODES];
        let nn = elem_coords(mesh, e, &mut x);
        let mut elem_dofs = Vec::with_capacity(3 * nn);
        setup.dofs.elem_dofs(mesh, e, &mut elem_dofs);
        let w = elem_dofs.len();
        let off = w - nn;
        // The thermal part, then placed in the leading `off × off` block.
        let mut rb = vec![0.0; off];
        let mut jb = vec![0.0; off * off];
        thermal(e, &mut jb, &mut rb);
        for i in 0..off {
            re[i] += rb[i];
            for j in 0..off {
                je[i * w + j] += jb[i * off + j];
            }
        }
        let mut te = [0.0; MAX_NODES];
        let mut ce = [0.0; MAX_NODES];
        for k in 0..nn {
            te[k] = u[elem_dofs[k] as usize];
            ce[k] = u[elem_dofs[off + k] as usize];
        }
        let failed = Cell::new(None);
        let d = checked(diffusivity, "diffusivity", t, &failed);
        crate::heat::species::species_residual_jacobian(
            rule,
            &x[..nn],
            &te[..nn],
            &ce[..nn],
            d,
            (off, w),
            re,
            je,
        )
        .map_err(|bad| bad_jacobian(mesh, e, bad))?;
        if let Some(message) = failed.take() {
            let block = mesh.blocks[b].id;
            return Err(HeatError::Material { block, message });
        }
        let fluxes = self.species_fluxes;
        for k in fluxes.of(e) {
            let (side, j) = loads.species_fluxes[k];
            influx(mesh, topo, &x[..nn], side.side, j, &mut re[off..off + nn]);
        }
        Ok(())
    }
}

/// A prescribed influx `j` (per area, into the body) on `side` of an element: its
/// residual rows get `−∫ j N_a dA`; it adds nothing to the Jacobian.
fn influx(
    mesh: &crate::mesh::Mesh,
    topo: crate::mesh::Topology,
    x: &[[f64; 3]],
    side: u8,
    j: f64,
    re: &mut [f64],
) {
    let mut f = [0.0; MAX_NODES];
    let f = &mut f[..x.len()];
    kernel::face_flux_with(Measure::of(mesh.axisymmetric), topo, x, side, |_| j, f);
    re.iter_mut().zip(f.iter()).for_each(|(r, f)| *r -= f);
}

/// A material law as a kernel calls it: a failure or a non-finite value is kept in
/// `failed` (the element reports it) and gives 0.
fn checked<'l>(
    law: &'l Law,
    what: &'static str,
    t: f64,
    failed: &'l Cell<Option<String>>,
) -> impl Fn(f64, [f64; 3]) -> (f64, f64) + 'l {
    move |temp, xq| match law.eval(temp, xq, t) {
        Ok(v) if v.0.is_finite() && v.1.is_finite() => v,
        Ok(v) => {
            failed.set(Some(format!("{what} = {} at T = {temp}", v.0)));
            (0.0, 0.0)
        }
        Err(m) => {
            failed.set(Some(format!("{what}: {m}")));
            (0.0, 0.0)
        }
    }
}
