//! PETSc through its C API: the few calls the distributed solve makes (a distributed AIJ
//! matrix, vectors, a KSP), declared by hand and wrapped so that every error code becomes
//! a [`PetscError`] naming the call, and every object is destroyed when dropped.
//!
//! Bound against Debian's `petsc-dev` (PETSc 3.18, `libpetsc_real`: real double
//! scalars, 32-bit `PetscInt` — `petscconf.h` has no `PETSC_USE_64BIT_INDICES`).
//! Linking `petsc_real` by name rules out a complex build; [`initialize`] asks the
//! library for its `PetscInt` width and refuses any other than 4 bytes, so a
//! 64-bit-index PETSc found at run time is an error, not a silent misread of indices.
//! Why our own 40 declarations rather than a crate: the one Rust binding of PETSc
//! (petsc-rs, with petsc-sys generating its bindings by bindgen) calls itself a work in
//! progress whose wrappers may be wrong, and would run bindgen over all of PETSc's
//! headers at every clean build for the handful of calls used here; each declaration
//! below was checked against Debian's 3.18 headers instead.

use std::ffi::{CStr, CString, c_char, c_int, c_void};

use mpi::ffi::MPI_Comm;

/// `PetscInt` of Debian's build (checked at start by [`initialize`]).
pub type PetscInt = i32;
type PetscErrorCode = c_int;
type Object = *mut c_void;

// The enum values below are those of PETSc 3.18's headers.
const INSERT_VALUES: c_int = 1;
const ADD_VALUES: c_int = 2;
const MAT_FINAL_ASSEMBLY: c_int = 0;
/// `MatReuse`: `MAT_INITIAL_MATRIX`, `MAT_REUSE_MATRIX`.
const MAT_INITIAL_MATRIX: c_int = 0;
const MAT_REUSE_MATRIX: c_int = 1;
/// `MatOption` `MAT_NEW_NONZERO_ALLOCATION_ERR`.
const MAT_NEW_NONZERO_ALLOCATION_ERR: c_int = 19;
const NORM_2: c_int = 1;
/// `KSPNormType` `KSP_NORM_UNPRECONDITIONED`: stop on the true residual ‖b − Ax‖.
const KSP_NORM_UNPRECONDITIONED: c_int = 2;
/// `PCSide` `PC_RIGHT`: GMRES then minimises the true residual.
const PC_RIGHT: c_int = 1;
/// `PCCompositeType` `PC_COMPOSITE_ADDITIVE`: the blocks' preconditioners side by side.
const PC_COMPOSITE_ADDITIVE: c_int = 0;
/// `PetscDataType` `PETSC_INT`.
const PETSC_INT: c_int = 16;
/// `PETSC_DEFAULT`: keep PETSc's value of a tolerance.
const PETSC_DEFAULT: f64 = -2.0;

#[link(name = "petsc_real")]
unsafe extern "C" {
    fn PetscInitializeNoArguments() -> PetscErrorCode;
    fn PetscFinalize() -> PetscErrorCode;
    fn PetscDataTypeGetSize(t: c_int, size: *mut usize) -> PetscErrorCode;
    fn PetscErrorMessage(
        code: PetscErrorCode,
        text: *mut *const c_char,
        specific: *mut *mut c_char,
    ) -> PetscErrorCode;
    fn PetscPushErrorHandler(
        handler: Option<
            unsafe extern "C" fn(
                MPI_Comm,
                c_int,
                *const c_char,
                *const c_char,
                PetscErrorCode,
                c_int,
                *const c_char,
                *mut c_void,
            ) -> PetscErrorCode,
        >,
        ctx: *mut c_void,
    ) -> PetscErrorCode;
    fn PetscReturnErrorHandler(
        comm: MPI_Comm,
        line: c_int,
        fun: *const c_char,
        file: *const c_char,
        n: PetscErrorCode,
        p: c_int,
        mess: *const c_char,
        ctx: *mut c_void,
    ) -> PetscErrorCode;

    fn MatCreate(comm: MPI_Comm, mat: *mut Object) -> PetscErrorCode;
    fn MatSetSizes(
        mat: Object,
        m: PetscInt,
        n: PetscInt,
        mm: PetscInt,
        nn: PetscInt,
    ) -> PetscErrorCode;
    fn MatSetType(mat: Object, t: *const c_char) -> PetscErrorCode;
    fn MatSeqAIJSetPreallocation(mat: Object, nz: PetscInt, nnz: *const PetscInt)
    -> PetscErrorCode;
    fn MatMPIAIJSetPreallocation(
        mat: Object,
        d_nz: PetscInt,
        d_nnz: *const PetscInt,
        o_nz: PetscInt,
        o_nnz: *const PetscInt,
    ) -> PetscErrorCode;
    fn MatSetValues(
        mat: Object,
        m: PetscInt,
        rows: *const PetscInt,
        n: PetscInt,
        cols: *const PetscInt,
        v: *const f64,
        mode: c_int,
    ) -> PetscErrorCode;
    fn MatAssemblyBegin(mat: Object, t: c_int) -> PetscErrorCode;
    fn MatAssemblyEnd(mat: Object, t: c_int) -> PetscErrorCode;
    fn MatZeroEntries(mat: Object) -> PetscErrorCode;
    fn MatZeroRowsColumns(
        mat: Object,
        n: PetscInt,
        rows: *const PetscInt,
        diag: f64,
        x: Object,
        b: Object,
    ) -> PetscErrorCode;
    fn MatMult(mat: Object, x: Object, y: Object) -> PetscErrorCode;
    fn MatMultTranspose(mat: Object, x: Object, y: Object) -> PetscErrorCode;
    fn MatPtAP(a: Object, p: Object, reuse: c_int, fill: f64, c: *mut Object) -> PetscErrorCode;
    fn MatGetRow(
        mat: Object,
        row: PetscInt,
        ncols: *mut PetscInt,
        cols: *mut *const PetscInt,
        vals: *mut *const f64,
    ) -> PetscErrorCode;
    fn MatRestoreRow(
        mat: Object,
        row: PetscInt,
        ncols: *mut PetscInt,
        cols: *mut *const PetscInt,
        vals: *mut *const f64,
    ) -> PetscErrorCode;
    fn MatSetOption(mat: Object, option: c_int, flag: c_int) -> PetscErrorCode;
    fn MatDestroy(mat: *mut Object) -> PetscErrorCode;

    fn VecCreateMPI(comm: MPI_Comm, n: PetscInt, nn: PetscInt, v: *mut Object) -> PetscErrorCode;
    fn VecDuplicate(v: Object, out: *mut Object) -> PetscErrorCode;
    fn VecSetValues(
        v: Object,
        n: PetscInt,
        ix: *const PetscInt,
        y: *const f64,
        mode: c_int,
    ) -> PetscErrorCode;
    fn VecAssemblyBegin(v: Object) -> PetscErrorCode;
    fn VecAssemblyEnd(v: Object) -> PetscErrorCode;
    fn VecZeroEntries(v: Object) -> PetscErrorCode;
    fn VecNorm(v: Object, t: c_int, out: *mut f64) -> PetscErrorCode;
    fn VecGetArray(v: Object, a: *mut *mut f64) -> PetscErrorCode;
    fn VecRestoreArray(v: Object, a: *mut *mut f64) -> PetscErrorCode;
    fn VecDestroy(v: *mut Object) -> PetscErrorCode;

    fn KSPCreate(comm: MPI_Comm, ksp: *mut Object) -> PetscErrorCode;
    fn KSPSetOperators(ksp: Object, a: Object, p: Object) -> PetscErrorCode;
    fn KSPSetType(ksp: Object, t: *const c_char) -> PetscErrorCode;
    fn KSPGetPC(ksp: Object, pc: *mut Object) -> PetscErrorCode;
    fn PCSetType(pc: Object, t: *const c_char) -> PetscErrorCode;
    fn PCFactorSetMatSolverType(pc: Object, t: *const c_char) -> PetscErrorCode;
    fn KSPSetTolerances(
        ksp: Object,
        rtol: f64,
        abstol: f64,
        dtol: f64,
        maxits: PetscInt,
    ) -> PetscErrorCode;
    fn KSPSetFromOptions(ksp: Object) -> PetscErrorCode;
    fn KSPSetInitialGuessNonzero(ksp: Object, flag: c_int) -> PetscErrorCode;
    fn KSPSetNormType(ksp: Object, t: c_int) -> PetscErrorCode;
    fn KSPSetPCSide(ksp: Object, side: c_int) -> PetscErrorCode;
    fn PCFieldSplitSetType(pc: Object, t: c_int) -> PetscErrorCode;
    fn PCFieldSplitSetIS(pc: Object, name: *const c_char, is: Object) -> PetscErrorCode;
    fn ISCreateStride(
        comm: MPI_Comm,
        n: PetscInt,
        first: PetscInt,
        step: PetscInt,
        is: *mut Object,
    ) -> PetscErrorCode;
    fn ISDestroy(is: *mut Object) -> PetscErrorCode;
    fn PetscOptionsSetValue(
        options: Object,
        name: *const c_char,
        value: *const c_char,
    ) -> PetscErrorCode;
    fn PetscOptionsHasName(
        options: Object,
        prefix: *const c_char,
        name: *const c_char,
        set: *mut c_int,
    ) -> PetscErrorCode;
    fn KSPGetGuess(ksp: Object, guess: *mut Object) -> PetscErrorCode;
    fn KSPGuessSetType(guess: Object, t: *const c_char) -> PetscErrorCode;
    fn KSPGuessFischerSetModel(guess: Object, model: PetscInt, size: PetscInt) -> PetscErrorCode;
    fn KSPSetUp(ksp: Object) -> PetscErrorCode;
    fn KSPSetReusePreconditioner(ksp: Object, flag: c_int) -> PetscErrorCode;
    fn KSPSolve(ksp: Object, b: Object, x: Object) -> PetscErrorCode;
    fn KSPGetIterationNumber(ksp: Object, its: *mut PetscInt) -> PetscErrorCode;
    fn KSPGetConvergedReason(ksp: Object, reason: *mut c_int) -> PetscErrorCode;
    fn KSPDestroy(ksp: *mut Object) -> PetscErrorCode;
}

/// A PETSc call that returned an error code.
#[derive(Debug, Clone, thiserror::Error)]
#[error("PETSc {call} failed (error {code}: {message})")]
pub struct PetscError {
    pub call: &'static str,
    pub code: i32,
    pub message: String,
}

impl PetscError {
    /// The Krylov solve ran and diverged (a negative `KSPConvergedReason`), as opposed
    /// to a call that failed: the same on every rank, and a step may be retried.
    pub fn is_divergence(&self) -> bool {
        self.call == "KSPSolve" && self.code < 0
    }
}

fn check(call: &'static str, code: PetscErrorCode) -> Result<(), PetscError> {
    if code == 0 {
        return Ok(());
    }
    let mut text: *const c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage writes a pointer to a static string (or leaves null).
    unsafe { PetscErrorMessage(code, &mut text, std::ptr::null_mut()) };
    let message = if text.is_null() {
        "no message".to_string()
    } else {
        // SAFETY: non-null, a NUL-terminated static string of PETSc's.
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    };
    Err(PetscError {
        call,
        code,
        message,
    })
}

/// Start PETSc on an MPI already initialised (PETSc then leaves MPI to its owner), with
/// errors returned as codes rather than printed tracebacks, and check that the library's
/// `PetscInt` is the 32-bit integer these declarations assume.
pub fn initialize() -> Result<(), PetscError> {
    // SAFETY: plain calls; MPI is initialised by the caller (rsmpi).
    unsafe {
        check("PetscInitialize", PetscInitializeNoArguments())?;
        check(
            "PetscPushErrorHandler",
            PetscPushErrorHandler(Some(PetscReturnErrorHandler), std::ptr::null_mut()),
        )?;
    }
    let mut size = 0usize;
    // SAFETY: writes one size_t.
    check("PetscDataTypeGetSize", unsafe {
        PetscDataTypeGetSize(PETSC_INT, &mut size)
    })?;
    if size != std::mem::size_of::<PetscInt>() {
        return Err(PetscError {
            call: "PetscDataTypeGetSize",
            code: 0,
            message: format!(
                "this PETSc has {size}-byte PetscInt; seam is bound to Debian's 4-byte build (libpetsc_real)"
            ),
        });
    }
    Ok(())
}

/// End PETSc (before MPI ends).
pub fn finalize() {
    // SAFETY: called once, after every PETSc object is dropped.
    unsafe { PetscFinalize() };
}

fn c_name(s: &str) -> CString {
    CString::new(s).expect("no NUL in a PETSc type name")
}

/// A distributed AIJ matrix with rows `[start, start + local)` on this rank.
pub struct Mat(Object);

impl Mat {
    /// A square `global × global` matrix, `local` rows here, preallocated exactly:
    /// `diagonal[i]` entries of local row `i` in the local column block, `off[i]` outside.
    pub fn aij(
        comm: MPI_Comm,
        local: usize,
        global: usize,
        diagonal: &[PetscInt],
        off: &[PetscInt],
    ) -> Result<Mat, PetscError> {
        let mut m: Object = std::ptr::null_mut();
        let aij = c_name("aij");
        // SAFETY: the preallocation arrays have `local` entries each.
        unsafe {
            check("MatCreate", MatCreate(comm, &mut m))?;
            let mat = Mat(m);
            check(
                "MatSetSizes",
                MatSetSizes(
                    m,
                    local as PetscInt,
                    local as PetscInt,
                    global as _,
                    global as _,
                ),
            )?;
            check("MatSetType", MatSetType(m, aij.as_ptr()))?;
            // Only the call matching the matrix's actual type (one rank: sequential) acts.
            check(
                "MatSeqAIJSetPreallocation",
                MatSeqAIJSetPreallocation(m, 0, diagonal.as_ptr()),
            )?;
            check(
                "MatMPIAIJSetPreallocation",
                MatMPIAIJSetPreallocation(m, 0, diagonal.as_ptr(), 0, off.as_ptr()),
            )?;
            Ok(mat)
        }
    }

    /// `y = A x` (collective; the matrix assembled).
    pub fn mult(&self, x: &Vector, y: &mut Vector) -> Result<(), PetscError> {
        // SAFETY: valid handles with the matrix's layout.
        check("MatMult", unsafe { MatMult(self.0, x.0, y.0) })
    }

    /// `y = Aᵀ x` (collective; the matrix assembled).
    pub fn mult_transpose(&self, x: &Vector, y: &mut Vector) -> Result<(), PetscError> {
        // SAFETY: valid handles with the matrix's layout.
        check("MatMultTranspose", unsafe {
            MatMultTranspose(self.0, x.0, y.0)
        })
    }

    /// `Pᵀ A P` (collective; both assembled, `p` square of `a`'s layout), made anew
    /// into `out` when it is `None`, else its values made again in place (the same
    /// patterns).
    pub fn ptap_into(&self, p: &Mat, out: &mut Option<Mat>) -> Result<(), PetscError> {
        // SAFETY: valid handles; PETSc writes the product's handle, or reuses it.
        unsafe {
            match out {
                Some(c) => check(
                    "MatPtAP",
                    MatPtAP(self.0, p.0, MAT_REUSE_MATRIX, PETSC_DEFAULT, &mut c.0),
                ),
                None => {
                    let mut c: Object = std::ptr::null_mut();
                    check(
                        "MatPtAP",
                        MatPtAP(self.0, p.0, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &mut c),
                    )?;
                    *out = Some(Mat(c));
                    Ok(())
                }
            }
        }
    }

    /// Row `row`'s stored columns and values (global indices; the row owned here, the
    /// matrix assembled).
    pub fn row(&self, row: PetscInt) -> Result<(Vec<PetscInt>, Vec<f64>), PetscError> {
        let (mut n, mut cols, mut vals) = (0, std::ptr::null(), std::ptr::null());
        // SAFETY: PETSc lends `n` columns and values until the row is restored; they
        // are copied first.
        unsafe {
            check(
                "MatGetRow",
                MatGetRow(self.0, row, &mut n, &mut cols, &mut vals),
            )?;
            let n_usize = n as usize;
            let copied = match n_usize {
                0 => (Vec::new(), Vec::new()),
                _ => (
                    std::slice::from_raw_parts(cols, n_usize).to_vec(),
                    std::slice::from_raw_parts(vals, n_usize).to_vec(),
                ),
            };
            check(
                "MatRestoreRow",
                MatRestoreRow(self.0, row, &mut n, &mut cols, &mut vals),
            )?;
            Ok(copied)
        }
    }

    /// Let entries beyond the preallocation in (each one found room for at some cost):
    /// for a matrix whose row lengths only the assembly knows.
    pub fn allow_new_entries(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid matrix; `PETSC_FALSE` is 0.
        check("MatSetOption", unsafe {
            MatSetOption(self.0, MAT_NEW_NONZERO_ALLOCATION_ERR, 0)
        })
    }

    /// Add `values[k]` at `(rows[k], col)` (global indices, any rank's rows).
    pub fn add_column(
        &mut self,
        rows: &[PetscInt],
        col: PetscInt,
        values: &[f64],
    ) -> Result<(), PetscError> {
        debug_assert_eq!(rows.len(), values.len());
        // SAFETY: `rows` and `values` have the length passed; one column.
        check("MatSetValues", unsafe {
            MatSetValues(
                self.0,
                rows.len() as PetscInt,
                rows.as_ptr(),
                1,
                &col,
                values.as_ptr(),
                ADD_VALUES,
            )
        })
    }

    /// Add `values[k]` at `(row, cols[k])` (global indices, any rank's row; columns
    /// ascending are found fastest).
    pub fn add_row(
        &mut self,
        row: PetscInt,
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<(), PetscError> {
        self.row_values(row, cols, values, ADD_VALUES)
    }

    /// Set row `row`'s entries at columns `cols` (global indices; the row owned here).
    pub fn set_row(
        &mut self,
        row: PetscInt,
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<(), PetscError> {
        self.row_values(row, cols, values, INSERT_VALUES)
    }

    /// One row's values, added or set by `mode`.
    fn row_values(
        &mut self,
        row: PetscInt,
        cols: &[PetscInt],
        values: &[f64],
        mode: c_int,
    ) -> Result<(), PetscError> {
        assert_eq!(cols.len(), values.len(), "one value per column");
        // SAFETY: `cols` and `values` have the length passed; one row.
        check("MatSetValues", unsafe {
            MatSetValues(
                self.0,
                1,
                &row,
                cols.len() as PetscInt,
                cols.as_ptr(),
                values.as_ptr(),
                mode,
            )
        })
    }

    pub fn zero(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid matrix.
        check("MatZeroEntries", unsafe { MatZeroEntries(self.0) })
    }

    /// Finish the values set so far (collective: off-rank entries travel here).
    pub fn assemble(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid matrix; collective on every rank.
        unsafe {
            check(
                "MatAssemblyBegin",
                MatAssemblyBegin(self.0, MAT_FINAL_ASSEMBLY),
            )?;
            check("MatAssemblyEnd", MatAssemblyEnd(self.0, MAT_FINAL_ASSEMBLY))
        }
    }

    /// Rows and columns `rows` (global, owned here) replaced by the identity's: the
    /// Dirichlet rows of an increment, symmetry kept.
    pub fn zero_rows_columns(&mut self, rows: &[PetscInt]) -> Result<(), PetscError> {
        // SAFETY: `rows` has the length passed; null x and b leave vectors alone.
        check("MatZeroRowsColumns", unsafe {
            MatZeroRowsColumns(
                self.0,
                rows.len() as PetscInt,
                rows.as_ptr(),
                1.0,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
            )
        })
    }
}

impl Drop for Mat {
    fn drop(&mut self) {
        // SAFETY: destroyed once.
        unsafe { MatDestroy(&mut self.0) };
    }
}

/// A distributed vector.
pub struct Vector(Object);

impl Vector {
    pub fn new(comm: MPI_Comm, local: usize, global: usize) -> Result<Vector, PetscError> {
        let mut v: Object = std::ptr::null_mut();
        // SAFETY: writes one handle.
        check("VecCreateMPI", unsafe {
            VecCreateMPI(comm, local as PetscInt, global as PetscInt, &mut v)
        })?;
        Ok(Vector(v))
    }

    pub fn duplicate(&self) -> Result<Vector, PetscError> {
        let mut v: Object = std::ptr::null_mut();
        // SAFETY: writes one handle.
        check("VecDuplicate", unsafe { VecDuplicate(self.0, &mut v) })?;
        Ok(Vector(v))
    }

    pub fn zero(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid vector.
        check("VecZeroEntries", unsafe { VecZeroEntries(self.0) })
    }

    /// Add `values[k]` at global index `at[k]` (any rank's entries).
    pub fn add(&mut self, at: &[PetscInt], values: &[f64]) -> Result<(), PetscError> {
        debug_assert_eq!(at.len(), values.len());
        // SAFETY: both slices have the length passed.
        check("VecSetValues", unsafe {
            VecSetValues(
                self.0,
                at.len() as PetscInt,
                at.as_ptr(),
                values.as_ptr(),
                ADD_VALUES,
            )
        })
    }

    /// Set `values[k]` at global index `at[k]`.
    pub fn set(&mut self, at: &[PetscInt], values: &[f64]) -> Result<(), PetscError> {
        // SAFETY: both slices have the length passed.
        check("VecSetValues", unsafe {
            VecSetValues(
                self.0,
                at.len() as PetscInt,
                at.as_ptr(),
                values.as_ptr(),
                INSERT_VALUES,
            )
        })
    }

    /// Finish the values set so far (collective).
    pub fn assemble(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid vector; collective on every rank.
        unsafe {
            check("VecAssemblyBegin", VecAssemblyBegin(self.0))?;
            check("VecAssemblyEnd", VecAssemblyEnd(self.0))
        }
    }

    /// ‖v‖₂ over every rank (collective).
    pub fn norm(&self) -> Result<f64, PetscError> {
        let mut n = 0.0;
        // SAFETY: writes one real.
        check("VecNorm", unsafe { VecNorm(self.0, NORM_2, &mut n) })?;
        Ok(n)
    }

    /// The entries this rank owns, handed to `f` to read or change.
    pub fn with_local<R>(
        &mut self,
        local: usize,
        f: impl FnOnce(&mut [f64]) -> R,
    ) -> Result<R, PetscError> {
        let mut a: *mut f64 = std::ptr::null_mut();
        // SAFETY: PETSc hands the local array (`local` entries, the size the vector was
        // made with) until VecRestoreArray; nothing else touches the vector meanwhile.
        unsafe {
            check("VecGetArray", VecGetArray(self.0, &mut a))?;
            let r = f(if local == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(a, local)
            });
            check("VecRestoreArray", VecRestoreArray(self.0, &mut a))?;
            Ok(r)
        }
    }
}

impl Drop for Vector {
    fn drop(&mut self) {
        // SAFETY: destroyed once.
        unsafe { VecDestroy(&mut self.0) };
    }
}

/// Which Krylov method and preconditioner a [`Ksp`] runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// CG preconditioned by hypre's BoomerAMG through PETSc (symmetric positive
    /// definite), with the settings of [`BOOMERAMG`].
    CgAmg,
    /// A direct LU factorisation by MUMPS (small, unsymmetric or indefinite systems).
    MumpsLu,
    /// GMRES, right-preconditioned, by BoomerAMG (the settings of [`BOOMERAMG`]) on two
    /// diagonal blocks side by side (PETSc's additive field split): the coupled
    /// thermal–electrical Jacobian.
    GmresBlocks,
    /// GMRES, right-preconditioned, by BoomerAMG (the settings of [`BOOMERAMG`]) on the
    /// whole matrix: an unsymmetric Jacobian of one field (a temperature-dependent
    /// conductivity or conductance) beyond the size for a factorisation.
    GmresAmg,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::CgAmg => "PETSc CG + BoomerAMG",
            Method::MumpsLu => "PETSc MUMPS LU",
            Method::GmresBlocks => "PETSc GMRES + field-split BoomerAMG",
            Method::GmresAmg => "PETSc GMRES + BoomerAMG",
        }
    }
}

/// BoomerAMG's settings for [`Method::CgAmg`] and for each block of
/// [`Method::GmresBlocks`] (there as `-fieldsplit_0_…`, `-fieldsplit_1_…`), each unless
/// `PETSC_OPTIONS` gives it:
/// hypre's recommendations for 3-D problems — HMIS coarsening, extended+i
/// interpolation of at most 4 entries a row, strength threshold 0.5 — with aggressive
/// coarsening on the finest level — and each smoothing sweep through the rows in their
/// order rather than C points then F points (`no_CF`: one pass over the matrix a sweep
/// instead of two). On the electronics warm-up at refine 6 (thin fins and die, cells of
/// aspect 5; docs/parallel.md) its first 10 steps took 137 CG iterations and 3.1 s,
/// where GAMG with its defaults took 553 and 9.2 s and BoomerAMG with its own defaults
/// 91 iterations at five times the cost of each; the rows in order took 104 CG
/// iterations where C then F took 112, and a V-cycle a quarter less time (2026-12-07,
/// docs/parallel.md).
pub const BOOMERAMG: [(&str, &str); 7] = [
    ("-pc_hypre_type", "boomeramg"),
    ("-pc_hypre_boomeramg_coarsen_type", "HMIS"),
    ("-pc_hypre_boomeramg_interp_type", "ext+i"),
    ("-pc_hypre_boomeramg_P_max", "4"),
    ("-pc_hypre_boomeramg_strong_threshold", "0.5"),
    ("-pc_hypre_boomeramg_agg_nl", "1"),
    ("-pc_hypre_boomeramg_no_CF", "true"),
];

/// Whether PETSc's options (`PETSC_OPTIONS`, the command line) name `name`.
fn has_option(name: &str) -> Result<bool, PetscError> {
    let mut set: c_int = 0;
    let key = c_name(name);
    // SAFETY: the global options database, a NUL-terminated name, an int out.
    check("PetscOptionsHasName", unsafe {
        PetscOptionsHasName(
            std::ptr::null_mut(),
            std::ptr::null(),
            key.as_ptr(),
            &mut set,
        )
    })?;
    Ok(set != 0)
}

/// Set option `name` to `value` unless the user's options already name it.
fn default_option(name: &str, value: &str) -> Result<(), PetscError> {
    if has_option(name)? {
        return Ok(());
    }
    let (key, value) = (c_name(name), c_name(value));
    // SAFETY: the global options database, NUL-terminated strings PETSc copies.
    check("PetscOptionsSetValue", unsafe {
        PetscOptionsSetValue(std::ptr::null_mut(), key.as_ptr(), value.as_ptr())
    })
}

/// A linear solver over one matrix (PETSc options such as `-ksp_type` given in
/// `PETSC_OPTIONS` override the choice).
pub struct Ksp(Object);

/// Where a [`Method::GmresBlocks`] splits the unknowns: this rank's rows and the first
/// global row of the second block (rows below it are the first block).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Split {
    pub rows: std::ops::Range<usize>,
    pub at: usize,
}

impl Ksp {
    /// A solver of `a` by `method` (relative tolerance `rtol` for the Krylov methods);
    /// `split` is needed by [`Method::GmresBlocks`] alone.
    pub fn new(comm: MPI_Comm, a: &Mat, method: Method, rtol: f64) -> Result<Ksp, PetscError> {
        Self::with_split(comm, a, method, rtol, None)
    }

    pub fn with_split(
        comm: MPI_Comm,
        a: &Mat,
        method: Method,
        rtol: f64,
        split: Option<&Split>,
    ) -> Result<Ksp, PetscError> {
        let mut k: Object = std::ptr::null_mut();
        let mut pc: Object = std::ptr::null_mut();
        // SAFETY: plain calls on handles PETSc made; the names are NUL-terminated.
        unsafe {
            check("KSPCreate", KSPCreate(comm, &mut k))?;
            let ksp = Ksp(k);
            check("KSPSetOperators", KSPSetOperators(k, a.0, a.0))?;
            check("KSPGetPC", KSPGetPC(k, &mut pc))?;
            match method {
                Method::CgAmg | Method::GmresAmg => {
                    if method == Method::CgAmg {
                        check("KSPSetType", KSPSetType(k, c_name("cg").as_ptr()))?;
                    } else {
                        check("KSPSetType", KSPSetType(k, c_name("gmres").as_ptr()))?;
                        check("KSPSetPCSide", KSPSetPCSide(k, PC_RIGHT))?;
                    }
                    // A `-pc_type` of the user's is left to `KSPSetFromOptions` (so that
                    // a PETSc built without hypre can still run with `-pc_type gamg`);
                    // BoomerAMG's settings hold for a `-pc_type hypre` too.
                    if !has_option("-pc_type")? {
                        check("PCSetType", PCSetType(pc, c_name("hypre").as_ptr()))?;
                    }
                    for (name, value) in BOOMERAMG {
                        default_option(name, value)?;
                    }
                    check(
                        "KSPSetTolerances",
                        KSPSetTolerances(k, rtol, 1e-300, PETSC_DEFAULT, 10_000),
                    )?;
                }
                Method::GmresBlocks => {
                    let split = split.ok_or(PetscError {
                        call: "PCFieldSplitSetIS",
                        code: 0,
                        message: "GMRES by blocks needs where the blocks split".into(),
                    })?;
                    check("KSPSetType", KSPSetType(k, c_name("gmres").as_ptr()))?;
                    check("KSPSetPCSide", KSPSetPCSide(k, PC_RIGHT))?;
                    check(
                        "KSPSetTolerances",
                        KSPSetTolerances(k, rtol, 1e-300, PETSC_DEFAULT, 10_000),
                    )?;
                    check("PCSetType", PCSetType(pc, c_name("fieldsplit").as_ptr()))?;
                    check(
                        "PCFieldSplitSetType",
                        PCFieldSplitSetType(pc, PC_COMPOSITE_ADDITIVE),
                    )?;
                    let (rows, at) = (&split.rows, split.at);
                    let blocks = [rows.start..rows.end.min(at), rows.start.max(at)..rows.end];
                    for (name, block) in ["0", "1"].into_iter().zip(blocks) {
                        let mut is: Object = std::ptr::null_mut();
                        let count = block.end.saturating_sub(block.start);
                        check(
                            "ISCreateStride",
                            ISCreateStride(comm, count as _, block.start as _, 1, &mut is),
                        )?;
                        let set = PCFieldSplitSetIS(pc, c_name(name).as_ptr(), is);
                        ISDestroy(&mut is);
                        check("PCFieldSplitSetIS", set)?;
                        // Each block: one V-cycle of BoomerAMG with its settings (the
                        // split's own Krylov method is `preonly` by default), each
                        // unless the user's options say otherwise.
                        let prefix = format!("-fieldsplit_{name}_");
                        default_option(&format!("{prefix}pc_type"), "hypre")?;
                        for (option, value) in BOOMERAMG {
                            default_option(&option.replacen('-', &prefix, 1), value)?;
                        }
                    }
                }
                Method::MumpsLu => {
                    check("KSPSetType", KSPSetType(k, c_name("preonly").as_ptr()))?;
                    check("PCSetType", PCSetType(pc, c_name("lu").as_ptr()))?;
                    check(
                        "PCFactorSetMatSolverType",
                        PCFactorSetMatSolverType(pc, c_name("mumps").as_ptr()),
                    )?;
                }
            }
            check("KSPSetFromOptions", KSPSetFromOptions(k))?;
            Ok(ksp)
        }
    }

    /// Solves of one matrix that follow each other (time steps): start each from the
    /// combination of the last `count` solutions that is best in the energy norm
    /// (Fischer's projection, PETSc's `KSPGUESSFISCHER`, model 2: the solutions and
    /// their products), as seam's serial AMG-CG does. PETSc forgets them when the
    /// matrix's values change. For a solve from 0 only ([`Ksp::start_from_x`] false).
    pub fn remember_solutions(&mut self, count: usize) -> Result<(), PetscError> {
        let mut guess: Object = std::ptr::null_mut();
        // SAFETY: a valid KSP; the guess object is the KSP's own (not destroyed here).
        unsafe {
            check("KSPGetGuess", KSPGetGuess(self.0, &mut guess))?;
            check(
                "KSPGuessSetType",
                KSPGuessSetType(guess, c_name("fischer").as_ptr()),
            )?;
            check(
                "KSPGuessFischerSetModel",
                KSPGuessFischerSetModel(guess, 2, count as PetscInt),
            )
        }
    }

    /// Krylov methods: start from the `x` given to [`Ksp::solve`] (else from 0), and
    /// stop on the true residual relative to ‖b‖ — the serial AMG-CG's rule.
    pub fn start_from_x(&mut self, nonzero: bool) -> Result<(), PetscError> {
        // SAFETY: a valid KSP; PetscBool is an int.
        unsafe {
            check(
                "KSPSetInitialGuessNonzero",
                KSPSetInitialGuessNonzero(self.0, nonzero as c_int),
            )?;
            check(
                "KSPSetNormType",
                KSPSetNormType(self.0, KSP_NORM_UNPRECONDITIONED),
            )
        }
    }

    /// A Krylov method stops at ‖b − A x‖ ≤ max(`rtol` ‖b‖, `atol`) (with
    /// [`Ksp::start_from_x`]'s norm: the true residual).
    pub fn set_tolerances(&mut self, rtol: f64, atol: f64) -> Result<(), PetscError> {
        // SAFETY: a valid KSP.
        check("KSPSetTolerances", unsafe {
            KSPSetTolerances(self.0, rtol, atol, PETSC_DEFAULT, 10_000)
        })
    }

    /// Keep the preconditioner made last when the matrix's values change (`true`),
    /// or make it again at the next set-up or solve (`false`, PETSc's default).
    pub fn keep_preconditioner(&mut self, keep: bool) -> Result<(), PetscError> {
        // SAFETY: a valid KSP; PetscBool is an int.
        check("KSPSetReusePreconditioner", unsafe {
            KSPSetReusePreconditioner(self.0, keep as c_int)
        })
    }

    /// The preconditioner or factorisation made (collective).
    /// Solve with `a` from now on (its preconditioner made again at the next set-up).
    pub fn set_operators(&mut self, a: &Mat) -> Result<(), PetscError> {
        // SAFETY: valid handles; PETSc takes its own reference to the matrix.
        check("KSPSetOperators", unsafe {
            KSPSetOperators(self.0, a.0, a.0)
        })
    }

    pub fn set_up(&mut self) -> Result<(), PetscError> {
        // SAFETY: a valid KSP with operators.
        check("KSPSetUp", unsafe { KSPSetUp(self.0) })
    }

    /// Solve `A x = b`; the iterations taken, or an error when the method diverged.
    pub fn solve(&mut self, b: &Vector, x: &mut Vector) -> Result<usize, PetscError> {
        let (mut its, mut reason) = (0 as PetscInt, 0 as c_int);
        // SAFETY: valid handles; b and x have the matrix's layout.
        unsafe {
            check("KSPSolve", KSPSolve(self.0, b.0, x.0))?;
            check(
                "KSPGetIterationNumber",
                KSPGetIterationNumber(self.0, &mut its),
            )?;
            check(
                "KSPGetConvergedReason",
                KSPGetConvergedReason(self.0, &mut reason),
            )?;
        }
        if reason < 0 {
            return Err(PetscError {
                call: "KSPSolve",
                code: reason,
                message: format!(
                    "the Krylov solve diverged after {its} iterations (KSPConvergedReason {reason})"
                ),
            });
        }
        Ok(its.max(0) as usize)
    }
}

impl Drop for Ksp {
    fn drop(&mut self) {
        // SAFETY: destroyed once.
        unsafe { KSPDestroy(&mut self.0) };
    }
}
