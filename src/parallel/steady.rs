//! The steady solve on MPI: the Newton iteration of [`crate::heat::steady`] (the same
//! residual, Jacobian, Dirichlet rows on the increment and stopping tests) with the
//! system distributed.
//!
//! Each rank assembles the conduction of its own elements (a mesh of only those,
//! [`Layout::local_mesh`]) with the serial kernels and adds every entry it made — rows of
//! any rank: PETSc sends those to their owners at assembly. The interface terms likewise:
//! each rank evaluates the points it owns (the side-A points of its elements' faces, or
//! its side-A nodes; [`crate::heat::interfaces::Interfaces::own_points`]) and adds their
//! entries, in global (PETSc) dof numbers, to the rows of any rank; the heats are summed
//! over the ranks. The increment is solved by PETSc; each rank then gets from their
//! owners only the values it reads (its elements' dofs, and its points' on both sides:
//! [`Scatter`]), and the whole solution is gathered once, at the end, for the output.
//! Mortar ties with multipliers are refused.

use std::time::Instant;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, CommunicatorCollectives};

use crate::assembly::{Assembler, DofMap, Pattern};
use crate::heat::interfaces::InterfaceFailure;
use crate::heat::steady::{
    AMG_TOLERANCE, LinearMethod, LinearSolves, STEADY_AMG_TOLERANCE, SolveTiming, SteadyProblem,
    SteadySolution,
};
use crate::heat::{FaceBc, HeatError, TEMPERATURE, dirichlet_dofs};
use crate::mesh::{ElemId, Mesh, NodeId, Side};
use crate::solve::spmv_ref;
use faer::sparse::SparseColMatRef;

use super::part;
use super::petsc::{Ksp, Mat, Method, PetscError, PetscInt, Vector};
use super::session;

fn petsc_err(e: PetscError) -> HeatError {
    HeatError::Contact(format!("distributed solve: {e}"))
}

/// Solve `p` over the MPI world: on a run whose mesh is distributed (`p.mesh` this
/// rank's local mesh with its contact partners), rank 0 returns the whole solution and
/// every other rank its own part (its owned dofs and those it reads; the rest as they
/// started); else every rank the whole solution.
pub(super) fn solve(p: &SteadyProblem<'_>) -> Result<SteadySolution, HeatError> {
    let mesh = p.mesh;
    let world = session::comm();
    let comm = world.as_raw();
    let blocks = part::solid_blocks(mesh);
    let dofs = DofMap::new(mesh, &[(TEMPERATURE, &blocks)])?;
    let field = dofs
        .field(TEMPERATURE)
        .ok_or(HeatError::NoTemperatureField)?;
    let n = dofs.len();
    let bcs = dirichlet_dofs(mesh, &dofs, field, p.dirichlet)?;
    let iface = match p.interfaces {
        Some(i) if p.contact.is_empty() && p.ties.is_empty() => Some(i),
        None if p.contact.is_empty() && p.ties.is_empty() => None,
        _ => {
            return Err(refused(
                "interface terms given as ContactTerm/TieTerm lists",
            ));
        }
    };
    if let Some(i) = iface
        && !i.ties().map_err(HeatError::Contact)?.is_empty()
    {
        return Err(refused(
            "mortar ties with Lagrange multipliers (`Tied` with `Side B Variable`, standard or dual)",
        ));
    }
    let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
    let mut timing = SolveTiming::default();
    let t = Instant::now();
    part::ensure(mesh).map_err(HeatError::Contact)?;
    let layout = part::with(|part| Layout::new(part, mesh, &dofs, field))
        .ok_or_else(|| HeatError::Contact("distributed solve: no partition".into()))?
        .map_err(HeatError::Contact)?;
    let mut phases = Phases::default();
    phases.mark("partition", t);
    let rows = layout.rows();
    let mut u = vec![0.0; n];
    for &(d, g) in &bcs {
        u[d] = g;
    }

    // This rank's conduction: its elements, their face conditions, once (it is linear).
    let (local, to_local) = layout.local_mesh(mesh);
    let faces = local_faces(p.face_bcs, &to_local);
    let mut pattern = Pattern::new(&local, &dofs);
    pattern.build_direct()?;
    let k_sym = pattern.symbolic().expect("built").clone();
    let mut asm = Assembler::direct(&pattern)?;
    p.conduction_with_faces(&mut asm, &local, &dofs, &faces)?;
    let f_local = asm.rhs();
    let k_local = asm.take_values()?;
    drop(asm);
    drop(pattern);
    phases.mark("own elements", t);
    // The dofs whose residual this rank adds to: its elements' and its own.
    let mut touched: Vec<usize> = local
        .blocks
        .iter()
        .flat_map(|b| b.connectivity.iter())
        .filter_map(|&node| dofs.dof(field, node).map(|d| d.index()))
        .chain(layout.owned.iter().copied())
        .collect();
    drop(local);
    touched.sort_unstable();
    touched.dedup();
    let touched_petsc: Vec<PetscInt> = touched.iter().map(|&d| layout.petsc[d]).collect();

    // The interface terms of the points this rank owns (by their side-A face's element
    // or side-A node), all points again when the solve ends however it ends.
    let owns = |elem: Option<ElemId>, node: Option<NodeId>| match (elem, node) {
        (Some(e), _) => layout.elem_owner.get(e.index()).copied() == Some(layout.rank as u32),
        (None, Some(n)) => layout.node_owner.get(n.index()).copied() == Some(layout.rank as u32),
        (None, None) => false,
    };
    let _all_again = match iface {
        Some(i) => {
            i.own_points(Some(&owns)).map_err(failed)?;
            Some(AllPoints(i))
        }
        None => None,
    };
    // Their pattern: this rank's couplings alone (no elements).
    let empty = empty_mesh(mesh);
    let mut ipattern = Pattern::new(&empty, &dofs);
    let pairs_of_mine = match iface {
        Some(i) => i.couplings(&u, 0.0).map_err(failed)?,
        None => Vec::new(),
    };
    let first = ipattern.add_couplings(&pairs_of_mine)?.start;
    ipattern.build_direct()?;
    let i_sym = ipattern.symbolic().expect("built").clone();
    let mut iasm = Assembler::direct(&ipattern)?;
    // The couplings of every rank's points that reach this rank's rows, for their
    // preallocation.
    let reaching = couplings_to_owners(&world, &layout, &pairs_of_mine);
    {
        // How the partition meets the interfaces: couplings whose two dofs sit on
        // different ranks are those a per-rank solve would get wrong.
        let across = pairs_of_mine
            .iter()
            .filter(|&&(i, j)| layout.owner(i) != layout.owner(j))
            .count() as u64;
        let mine = [across, pairs_of_mine.len() as u64];
        let mut sum = [0u64; 2];
        world.all_reduce_into(&mine[..], &mut sum[..], SystemOperation::sum());
        let held = part::with(part::Part::counts).unwrap_or_default();
        let mut elems = vec![0u64; layout.size];
        world.all_gather_into(&(held.owned as u64), &mut elems[..]);
        if layout.rank == 0 {
            let dofs_per: Vec<usize> = layout.starts.windows(2).map(|w| w[1] - w[0]).collect();
            log::info!(
                "distributed over {} rank(s): elements per rank {elems:?}, dofs per rank {dofs_per:?}; {} of {} interface couplings join dofs of different ranks",
                elems.len(),
                sum[0],
                sum[1]
            );
        }
    }
    phases.mark("interface pattern", t);
    let (diagonal, off) = preallocation(mesh, &dofs, field, &layout, &reaching);
    drop(reaching);
    phases.mark("preallocation", t);
    let local_rows = rows.len();
    let global = layout.starts[layout.size];
    let mut a = Mat::aij(comm, local_rows, global, &diagonal, &off).map_err(petsc_err)?;
    let mut r_vec = Vector::new(comm, local_rows, global).map_err(petsc_err)?;
    let mut du_vec = r_vec.duplicate().map_err(petsc_err)?;
    let bc_rows: Vec<PetscInt> = bcs
        .iter()
        .filter(|&&(d, _)| layout.owns(d))
        .map(|&(d, _)| layout.petsc[d])
        .collect();
    let bc_local: Vec<usize> = bc_rows.iter().map(|&i| i as usize - rows.start).collect();
    // ‖F‖ over every rank, the scale of the stopping test.
    let f_values: Vec<f64> = touched.iter().map(|&d| f_local[d]).collect();
    r_vec.zero().map_err(petsc_err)?;
    r_vec.add(&touched_petsc, &f_values).map_err(petsc_err)?;
    r_vec.assemble().map_err(petsc_err)?;
    let f_norm = r_vec.norm().map_err(petsc_err)?;
    timing.assembly_s += t.elapsed().as_secs_f64();
    phases.mark("PETSc objects", t);
    if layout.rank == 0 {
        log::info!(
            "distributed set-up on rank 0 (s from its start): {}",
            phases.0
        );
    }

    let symmetric = iface.is_none_or(|i| i.is_linear());
    let method = if symmetric && p.iterative {
        Method::CgGamg
    } else {
        Method::MumpsLu
    };
    let tolerance = if method == Method::CgGamg {
        STEADY_AMG_TOLERANCE
    } else {
        AMG_TOLERANCE
    };
    let mut ksp = Ksp::new(comm, &a, method, tolerance).map_err(petsc_err)?;
    let mut linear = LinearSolves::default();
    let mut heat = Vec::new();
    let mut record = crate::heat::steady::Record::with_norm(f_norm, p.tolerance);
    let (mut converged, mut iterations) = (false, 0);
    let mut last_step = f64::INFINITY;
    // The dofs this rank reads: its elements' and its points' (side A and side B), their
    // starting values (a prescribed temperature held by another rank) from their owners.
    let scatter = Scatter::new(&world, &layout, &touched, &pairs_of_mine);
    scatter.start(&world, &layout, &mut u);
    for it in 0..=p.max_iterations {
        let t = Instant::now();
        // R = K u − F + Σ R_Γ: this rank's elements, and its own rows of the interfaces.
        let mut r = vec![0.0; n];
        spmv_ref(SparseColMatRef::new(k_sym.as_ref(), &k_local), &u, &mut r);
        for (ri, fi) in r.iter_mut().zip(&f_local) {
            *ri -= fi;
        }
        iasm.reset_couplings();
        let values: Vec<f64> = touched.iter().map(|&d| r[d]).collect();
        r_vec.zero().map_err(petsc_err)?;
        r_vec.add(&touched_petsc, &values).map_err(petsc_err)?;
        if let Some(i) = iface {
            // This rank's points' terms, into the rows of any rank.
            r.iter_mut().for_each(|x| *x = 0.0);
            let r_iface = &mut r;
            let mine = i
                .assemble(&u, 0.0, r_iface, &mut iasm, first)
                .map_err(failed)?;
            // A point reads the field where it has terms: there it must be kept.
            if let Some(d) = (0..n).find(|&d| r_iface[d] != 0.0 && !scatter.kept[d]) {
                return Err(HeatError::Contact(format!(
                    "distributed solve: an interface point of rank {} reads dof {d}, which it was not sent",
                    layout.rank
                )));
            }
            let (rows, values): (Vec<PetscInt>, Vec<f64>) = (0..n)
                .filter(|&d| r_iface[d] != 0.0)
                .map(|d| (layout.petsc[d], r_iface[d]))
                .unzip();
            r_vec.add(&rows, &values).map_err(petsc_err)?;
            heat = summed_heat(&world, &mine);
        }
        drop(r);
        r_vec.assemble().map_err(petsc_err)?;
        r_vec
            .with_local(local_rows, |v| bc_local.iter().for_each(|&i| v[i] = 0.0))
            .map_err(petsc_err)?;
        let rn = r_vec.norm().map_err(petsc_err)?;
        timing.assembly_s += t.elapsed().as_secs_f64();
        // The serial solve's stopping tests; they see |u| at its largest over the ranks
        // (they take only that).
        let u_max = [scatter.u_max(&world, &layout, &u)];
        if record.converged_at(it, rn, last_step, &u_max, symmetric) {
            converged = true;
            break;
        }
        if it == p.max_iterations {
            break;
        }
        iterations += 1;
        // J = K + J_Γ: every entry this rank made, the interface rows it owns.
        let t = Instant::now();
        a.zero().map_err(petsc_err)?;
        add_columns(&mut a, &k_sym, &k_local, &layout, |_| true)?;
        let mut i_values = Vec::new();
        iasm.values_into(&mut i_values)?;
        add_columns(&mut a, &i_sym, &i_values, &layout, |_| true)?;
        a.assemble().map_err(petsc_err)?;
        a.zero_rows_columns(&bc_rows).map_err(petsc_err)?;
        timing.assembly_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        ksp.set_up().map_err(petsc_err)?;
        timing.factor_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        // The increment: J Δu = −R (Δu = 0 on the Dirichlet rows, whose R is 0).
        r_vec
            .with_local(local_rows, |v| v.iter_mut().for_each(|x| *x = -*x))
            .map_err(petsc_err)?;
        let its = ksp.solve(&r_vec, &mut du_vec).map_err(petsc_err)?;
        let mine = du_vec
            .with_local(local_rows, |v| v.to_vec())
            .map_err(petsc_err)?;
        last_step = scatter.update(&world, &layout, &mine, &mut u);
        timing.solve_s += t.elapsed().as_secs_f64();
        linear.method = Some(match method {
            Method::CgGamg => LinearMethod::AmgCg,
            _ => LinearMethod::Lu,
        });
        if method == Method::CgGamg {
            linear.cg_iterations.push(its);
        }
    }
    // The whole solution, once: on rank 0 (which writes it) when the mesh is
    // distributed, else on every rank (every rank's output evaluates the interfaces at
    // it).
    let mine: Vec<f64> = layout.owned.iter().map(|&d| u[d]).collect();
    let whole = if layout.distributed {
        session::gather_root(&world, &mine)
    } else {
        session::gather_all(&world, &mine)
    };
    if whole.len() == global {
        for (d, ui) in u.iter_mut().enumerate() {
            *ui = whole[layout.petsc[d] as usize];
        }
    }
    let why = match (method, symmetric) {
        (Method::MumpsLu, true) => {
            "below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU"
        }
        (Method::MumpsLu, false) => {
            "a temperature-dependent conductance makes the Jacobian unsymmetric → MUMPS LU"
        }
        _ => "symmetric positive definite, at or above the AMG threshold → CG + GAMG",
    };
    super::record(method, why);
    let temperature = dofs.nodal_values(field, &u);
    Ok(SteadySolution {
        dofs,
        u,
        temperature,
        newton_iterations: iterations,
        converged,
        residual_history: record.history,
        heat,
        tie_heat: Vec::new(),
        crosspoints: Vec::new(),
        timing,
        linear,
    })
}

/// The dofs of one solve as PETSc sees them, on this rank: per local dof its PETSc
/// index, the rows of every rank, the dofs this rank owns, per local element and node
/// its owner (from the run's [`part::Part`]).
struct Layout {
    rank: usize,
    size: usize,
    /// Ranks other than 0 hold their part only (the solution is gathered on rank 0).
    distributed: bool,
    /// Per local dof, its PETSc index.
    petsc: Vec<PetscInt>,
    /// Rank `r`'s PETSc rows are `starts[r]..starts[r + 1]`.
    starts: Vec<usize>,
    /// The local dofs this rank owns, by PETSc index (consecutive).
    owned: Vec<usize>,
    elem_owner: Vec<u32>,
    node_owner: Vec<u32>,
}

impl Layout {
    fn new(
        part: &part::Part,
        mesh: &Mesh,
        dofs: &DofMap,
        field: crate::assembly::FieldId,
    ) -> Result<Layout, String> {
        if part.node_petsc.len() < mesh.num_nodes() || part.elem_owner.len() < mesh.num_elems() {
            return Err(format!(
                "distributed solve: the mesh has {} nodes and {} elements, this rank's part {} and {}",
                mesh.num_nodes(),
                mesh.num_elems(),
                part.node_petsc.len(),
                part.elem_owner.len()
            ));
        }
        let mut petsc = vec![-1 as PetscInt; dofs.len()];
        for k in 0..mesh.num_nodes() {
            if let Some(d) = dofs.dof(field, NodeId(k as u32)) {
                petsc[d.index()] = part.node_petsc[k];
            }
        }
        if let Some(d) = petsc.iter().position(|&i| i < 0) {
            return Err(format!(
                "distributed solve: dof {d} has no PETSc row (its node is on no partitioned block)"
            ));
        }
        let rows = part.rows();
        let mut owned: Vec<usize> = (0..dofs.len())
            .filter(|&d| rows.contains(&(petsc[d] as usize)))
            .collect();
        owned.sort_unstable_by_key(|&d| petsc[d]);
        if owned.len() != rows.len() {
            return Err(format!(
                "distributed solve: rank {} holds {} of its {} rows",
                part.rank,
                owned.len(),
                rows.len()
            ));
        }
        Ok(Layout {
            rank: part.rank,
            size: part.size,
            distributed: part.distributed,
            petsc,
            starts: part.starts.clone(),
            owned,
            elem_owner: (0..mesh.num_elems())
                .map(|e| part.elem_rank(ElemId(e as u32)) as u32)
                .collect(),
            node_owner: (0..mesh.num_nodes())
                .map(|n| part.node_rank(NodeId(n as u32)) as u32)
                .collect(),
        })
    }

    /// This rank's PETSc rows.
    fn rows(&self) -> std::ops::Range<usize> {
        self.starts[self.rank]..self.starts[self.rank + 1]
    }

    /// The rank owning local dof `d`.
    fn owner(&self, d: usize) -> usize {
        let i = self.petsc[d] as usize;
        self.starts.partition_point(|&s| s <= i) - 1
    }

    /// Whether local dof `d` is owned here.
    fn owns(&self, d: usize) -> bool {
        self.rows().contains(&(self.petsc[d] as usize))
    }

    /// The mesh of this rank's own elements: the same nodes and blocks (the blocks holding
    /// only this rank's elements, in their order), and per element of `mesh` its element
    /// there.
    fn local_mesh(&self, mesh: &Mesh) -> (Mesh, Vec<Option<ElemId>>) {
        let mut local = vec![None; mesh.num_elems()];
        let mut blocks = Vec::with_capacity(mesh.blocks.len());
        let mut elem_numbers = Vec::new();
        let mut next = 0u32;
        for block in &mesh.blocks {
            let nn = block.topology.node_count();
            let first_elem = ElemId(next);
            let mut connectivity = Vec::new();
            for (k, e) in block.elems().enumerate() {
                if self.elem_owner[e.index()] as usize == self.rank {
                    connectivity.extend_from_slice(&block.connectivity[k * nn..(k + 1) * nn]);
                    elem_numbers.push(mesh.elem_numbers[e.index()]);
                    local[e.index()] = Some(ElemId(next));
                    next += 1;
                }
            }
            blocks.push(crate::mesh::Block {
                id: block.id,
                name: block.name.clone(),
                topology: block.topology,
                connectivity,
                first_elem,
                thickness: block.thickness,
            });
        }
        let m = Mesh {
            dim: mesh.dim,
            coords: mesh.coords.clone(),
            node_numbers: mesh.node_numbers.clone(),
            elem_numbers,
            blocks,
            side_sets: Vec::new(),
            node_sets: Vec::new(),
            assemblies: Vec::new(),
            source: mesh.source.clone(),
            axisymmetric: mesh.axisymmetric,
        };
        (m, local)
    }
}

/// The increment's values a rank needs, brought from their owners each Newton step
/// (`MPI_Alltoallv` of the requested dofs' values) instead of gathering it whole.
struct Scatter {
    /// Per rank, the local dofs this rank asks of it, in the order its answers come.
    asks: Vec<Vec<usize>>,
    /// Per rank, the local rows (PETSc index − this rank's first row) it asks of us.
    asked: Vec<Vec<usize>>,
    /// Per local dof, whether this rank keeps it up to date (owned or asked).
    kept: Vec<bool>,
}

impl Scatter {
    /// Ask the owners of the `elements`' dofs and the `couplings`' dofs not owned here.
    fn new(
        world: &SimpleCommunicator,
        layout: &Layout,
        elements: &[usize],
        couplings: &[(usize, usize)],
    ) -> Scatter {
        let size = layout.size;
        let mut need: Vec<usize> = elements
            .iter()
            .copied()
            .chain(couplings.iter().flat_map(|&(i, j)| [i, j]))
            .filter(|&d| !layout.owns(d))
            .collect();
        need.sort_unstable();
        need.dedup();
        let mut asks = vec![Vec::new(); size];
        let mut kept = vec![false; layout.petsc.len()];
        for &d in &layout.owned {
            kept[d] = true;
        }
        for d in need {
            asks[layout.owner(d)].push(d);
            kept[d] = true;
        }
        let requests: Vec<Vec<i32>> = asks
            .iter()
            .map(|a| a.iter().map(|&d| layout.petsc[d]).collect())
            .collect();
        let first = layout.rows().start;
        let asked = session::exchange(world, &requests)
            .into_iter()
            .map(|r| r.into_iter().map(|i| i as usize - first).collect())
            .collect();
        Scatter { asks, asked, kept }
    }

    /// The owners' values of `mine` (this rank's rows) at the dofs this rank asked for,
    /// per rank in the order asked.
    fn bring(&self, world: &SimpleCommunicator, mine: &[f64]) -> Vec<Vec<f64>> {
        let answers: Vec<Vec<f64>> = self
            .asked
            .iter()
            .map(|rows| rows.iter().map(|&i| mine[i]).collect())
            .collect();
        session::exchange(world, &answers)
    }

    /// The starting values of the dofs asked for, as their owners hold them (a
    /// prescribed temperature at a node another rank holds).
    fn start(&self, world: &SimpleCommunicator, layout: &Layout, u: &mut [f64]) {
        let mine: Vec<f64> = layout.owned.iter().map(|&d| u[d]).collect();
        let got = self.bring(world, &mine);
        for (dofs, values) in self.asks.iter().zip(&got) {
            for (&d, &v) in dofs.iter().zip(values) {
                u[d] = v;
            }
        }
    }

    /// Add the increment (`mine`: this rank's rows) to `u` at the dofs owned or asked;
    /// returns its largest magnitude over every rank.
    fn update(
        &self,
        world: &SimpleCommunicator,
        layout: &Layout,
        mine: &[f64],
        u: &mut [f64],
    ) -> f64 {
        let first = layout.rows().start;
        let got = self.bring(world, mine);
        let mut step = 0.0f64;
        for &d in &layout.owned {
            let du = mine[layout.petsc[d] as usize - first];
            u[d] += du;
            step = step.max(du.abs());
        }
        for (dofs, values) in self.asks.iter().zip(&got) {
            for (&d, &du) in dofs.iter().zip(values) {
                u[d] += du;
            }
        }
        let mut largest = 0.0;
        world.all_reduce_into(&step, &mut largest, SystemOperation::max());
        largest
    }

    /// The largest |u| over the owned dofs of every rank.
    fn u_max(&self, world: &SimpleCommunicator, layout: &Layout, u: &[f64]) -> f64 {
        let mine = layout.owned.iter().fold(0.0f64, |m, &d| m.max(u[d].abs()));
        let mut largest = 0.0;
        world.all_reduce_into(&mine, &mut largest, SystemOperation::max());
        largest
    }
}

/// Evaluates every point again when dropped (the run's output after the solve sees the
/// whole interface).
struct AllPoints<'a>(&'a dyn crate::heat::interfaces::Interfaces);

impl Drop for AllPoints<'_> {
    fn drop(&mut self) {
        // The run's interfaces accepted the restriction, so they accept its end.
        let _ = self.0.own_points(None);
    }
}

/// The couplings (PETSc rows and columns) of every rank's points that fall in this
/// rank's rows: each rank sends each of its couplings `(i, j)` to the owners of row `i`
/// and of row `j` (`MPI_Alltoallv`).
fn couplings_to_owners(
    world: &SimpleCommunicator,
    layout: &Layout,
    mine: &[(usize, usize)],
) -> Vec<(usize, usize)> {
    let mut out: Vec<Vec<i32>> = vec![Vec::new(); layout.size];
    for &(i, j) in mine {
        let (pi, pj) = (layout.petsc[i], layout.petsc[j]);
        out[layout.owner(i)].extend_from_slice(&[pi, pj]);
        out[layout.owner(j)].extend_from_slice(&[pj, pi]);
    }
    session::exchange(world, &out)
        .into_iter()
        .flat_map(|v| {
            v.chunks_exact(2)
                .map(|c| (c[0] as usize, c[1] as usize))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Each interaction's heat (side A, side B) summed over the ranks' points.
fn summed_heat(world: &SimpleCommunicator, mine: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let flat: Vec<f64> = mine.iter().flat_map(|&(a, b)| [a, b]).collect();
    let mut sum = vec![0.0; flat.len()];
    world.all_reduce_into(&flat[..], &mut sum[..], SystemOperation::sum());
    sum.chunks_exact(2).map(|c| (c[0], c[1])).collect()
}

/// The set-up's phases, as seconds from its start, for the log.
#[derive(Default)]
struct Phases(String);

impl Phases {
    fn mark(&mut self, what: &str, since: Instant) {
        if !self.0.is_empty() {
            self.0.push_str(", ");
        }
        self.0
            .push_str(&format!("{what} {:.3}", since.elapsed().as_secs_f64()));
    }
}

/// The error refusing what the distributed solve does not do yet.
fn refused(what: &str) -> HeatError {
    HeatError::Contact(format!(
        "[E0902] {what}: not yet distributed under MPI (help: run without mpirun; docs/parallel.md lists what is distributed)"
    ))
}

/// The face conditions of this rank's elements, on its local mesh.
fn local_faces(faces: &[FaceBc], to_local: &[Option<ElemId>]) -> Vec<FaceBc> {
    faces
        .iter()
        .filter_map(|f| {
            let s = f.side();
            let elem = to_local.get(s.elem.index()).copied().flatten()?;
            let side = Side { elem, side: s.side };
            Some(match *f {
                FaceBc::Flux { q, .. } => FaceBc::Flux { side, q },
                FaceBc::Convection { h, t_inf, .. } => FaceBc::Convection { side, h, t_inf },
                FaceBc::Radiation {
                    emissivity, t_inf, ..
                } => FaceBc::Radiation {
                    side,
                    emissivity,
                    t_inf,
                },
            })
        })
        .collect()
}

/// `mesh` without elements: the pattern of the interface couplings alone.
fn empty_mesh(mesh: &Mesh) -> Mesh {
    Mesh {
        dim: mesh.dim,
        coords: Vec::new(),
        node_numbers: Vec::new(),
        elem_numbers: Vec::new(),
        blocks: mesh
            .blocks
            .iter()
            .map(|b| crate::mesh::Block {
                id: b.id,
                name: b.name.clone(),
                topology: b.topology,
                connectivity: Vec::new(),
                first_elem: ElemId(0),
                thickness: b.thickness,
            })
            .collect(),
        side_sets: Vec::new(),
        node_sets: Vec::new(),
        assemblies: Vec::new(),
        source: None,
        axisymmetric: mesh.axisymmetric,
    }
}

/// Add the CSC matrix (`sym`, `values`; serial dofs) to `a`, rows where `keep` holds.
fn add_columns(
    a: &mut Mat,
    sym: &faer::sparse::SymbolicSparseColMat<usize>,
    values: &[f64],
    layout: &Layout,
    keep: impl Fn(usize) -> bool,
) -> Result<(), HeatError> {
    let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
    let (mut rows, mut vals) = (Vec::new(), Vec::new());
    for j in 0..sym.ncols() {
        rows.clear();
        vals.clear();
        for k in col_ptr[j]..col_ptr[j + 1] {
            let i = row_idx[k];
            if values[k] != 0.0 && keep(i) {
                rows.push(layout.petsc[i]);
                vals.push(values[k]);
            }
        }
        if !rows.is_empty() {
            a.add_column(&rows, layout.petsc[j], &vals)
                .map_err(petsc_err)?;
        }
    }
    Ok(())
}

/// Exact preallocation of this rank's rows: per row, the columns of every element at
/// its node (all of them held here: a rank holds every element around the nodes it owns),
/// and the interface couplings `reaching` its rows (PETSc row, PETSc column), counted
/// inside and outside the rank's column block.
fn preallocation(
    mesh: &Mesh,
    dofs: &DofMap,
    field: crate::assembly::FieldId,
    layout: &Layout,
    reaching: &[(usize, usize)],
) -> (Vec<PetscInt>, Vec<PetscInt>) {
    let rows = layout.rows();
    let mut cols: Vec<Vec<usize>> = vec![Vec::new(); rows.len()];
    let local_row = |i: usize| -> Option<usize> { rows.contains(&i).then(|| i - rows.start) };
    let mut buf = Vec::new();
    for &b in dofs.field_blocks(field) {
        let nn = mesh.blocks[b].topology.node_count();
        for (k, _) in mesh.blocks[b].elems().enumerate() {
            buf.clear();
            buf.extend(
                mesh.blocks[b].connectivity[k * nn..(k + 1) * nn]
                    .iter()
                    .filter_map(|&node| dofs.dof(field, node))
                    .map(|d| layout.petsc[d.index()] as usize),
            );
            for &i in &buf {
                if let Some(r) = local_row(i) {
                    cols[r].extend_from_slice(&buf);
                }
            }
        }
    }
    for &(i, j) in reaching {
        if let Some(r) = local_row(i) {
            cols[r].push(j);
        }
    }
    let (mut diagonal, mut off) = (vec![0; rows.len()], vec![0; rows.len()]);
    for (r, c) in cols.iter_mut().enumerate() {
        c.push(rows.start + r);
        c.sort_unstable();
        c.dedup();
        for &i in c.iter() {
            if rows.contains(&i) {
                diagonal[r] += 1;
            } else {
                off[r] += 1;
            }
        }
    }
    (diagonal, off)
}
