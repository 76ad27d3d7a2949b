! seam_plugin.f90: the plugin ABI of seam (version 1.0) for Fortran, through iso_c_binding.
!
! Hand-kept mirror of seam_plugin.h: every type below is bind(c) and has the layout of the
! C struct of the same name; seam's tests compile a C and a Fortran program that print
! every size, offset and constant and compare the two (tests/it/fortran_plugin.rs).
!
! C's unsigned types have no Fortran kind: uint32_t fields are integer(c_int32_t) and the
! uint64_t capability flags integer(c_int64_t), with the same size and, for the values
! seam uses, the same bits. Pointers are type(c_ptr) (seam_integer_data, seam_real_data
! and seam_c_string turn them into Fortran arrays and strings); function pointers are
! type(c_funptr), made with c_funloc from procedures with the abstract interfaces below.
!
! A plugin is a shared library exporting
!     type(c_ptr) function seam_plugin_v1() bind(c, name="seam_plugin_v1")
! that returns c_loc of a descriptor with the save and target attributes. See
! docs/plugins.md ("Writing a plugin in Fortran") and plugins/examples/fortran_table.
module seam_plugin
    use, intrinsic :: iso_c_binding, only: c_int32_t, c_int64_t, c_size_t, c_double, &
        c_char, c_ptr, c_funptr, c_null_char, c_null_funptr, c_f_pointer, c_associated
    implicit none
    private

    integer(c_int32_t), parameter, public :: SEAM_PLUGIN_ABI_MAJOR = 1
    integer(c_int32_t), parameter, public :: SEAM_PLUGIN_ABI_MINOR = 0
    character(len=*), parameter, public :: SEAM_PLUGIN_ENTRY_SYMBOL = "seam_plugin_v1"
    integer, parameter, public :: SEAM_MESSAGE_LEN = 256

    ! Status codes.
    integer(c_int32_t), parameter, public :: SEAM_STATUS_OK = 0
    integer(c_int32_t), parameter, public :: SEAM_STATUS_ERROR = 1
    integer(c_int32_t), parameter, public :: SEAM_STATUS_CUTBACK = 2

    ! Capability flags.
    integer(c_int64_t), parameter, public :: SEAM_CAP_THREAD_SAFE = 1
    integer(c_int64_t), parameter, public :: SEAM_CAP_PROVIDES_DERIVATIVES = 2
    integer(c_int64_t), parameter, public :: SEAM_CAP_RETURNS_FLUX = 4
    integer(c_int64_t), parameter, public :: SEAM_CAP_HAS_STATE = 8
    integer(c_int64_t), parameter, public :: SEAM_CAP_ALL = 15

    ! Given once to init; the arrays are valid only during the call.
    type, bind(c), public :: seam_instance_in
        integer(c_int32_t) :: struct_size
        integer(c_int32_t) :: reserved
        type(c_ptr) :: model            ! const char *
        type(c_ptr) :: integer_data     ! const int64_t *
        integer(c_size_t) :: n_integer
        type(c_ptr) :: real_data        ! const double *
        integer(c_size_t) :: n_real
    end type seam_instance_in

    ! One contact point. gap > 0 open; pressure >= 0 in compression.
    type, bind(c), public :: seam_point_in
        integer(c_int32_t) :: struct_size
        integer(c_int32_t) :: reserved
        real(c_double) :: gap
        real(c_double) :: pressure
        real(c_double) :: temp_a
        real(c_double) :: temp_b
        real(c_double) :: x(3)
        real(c_double) :: normal_a(3)
        real(c_double) :: normal_b(3)
        real(c_double) :: weight
        real(c_double) :: time
        real(c_double) :: dt
        integer(c_int64_t) :: step
        integer(c_int64_t) :: iteration
        type(c_ptr) :: surface_a        ! const char *
        type(c_ptr) :: surface_b        ! const char *
        type(c_ptr) :: fields           ! const double *
        integer(c_size_t) :: n_fields
        type(c_ptr) :: integer_data     ! const int64_t *, a copy: writes are not kept
        integer(c_size_t) :: n_integer
        type(c_ptr) :: real_data        ! const double *, a copy
        integer(c_size_t) :: n_real
        type(c_ptr) :: state_old        ! const double *, the last accepted step
        type(c_ptr) :: state_new        ! double *, on entry a copy of state_old
        integer(c_size_t) :: n_state
    end type seam_point_in

    ! The result for one point; seam zeroes it and sets struct_size before a call.
    type, bind(c), public :: seam_point_out
        integer(c_int32_t) :: struct_size
        integer(c_int32_t) :: status
        real(c_double) :: value          ! conductance h, or flux q into side A
        real(c_double) :: d_temp_a
        real(c_double) :: d_temp_b
        real(c_double) :: d_gap
        real(c_double) :: d_pressure
        real(c_double) :: cutback_factor ! with SEAM_STATUS_CUTBACK: new/old step, 0 = host decides
        character(kind=c_char) :: message(SEAM_MESSAGE_LEN)
    end type seam_point_out

    type, bind(c), public :: seam_plugin_descriptor
        integer(c_int32_t) :: abi_major
        integer(c_int32_t) :: abi_minor
        integer(c_int32_t) :: struct_size
        integer(c_int32_t) :: state_size
        type(c_ptr) :: name             ! const char *
        type(c_ptr) :: model_version    ! const char *
        integer(c_int64_t) :: capabilities
        type(c_funptr) :: init = c_null_funptr           ! may be null
        type(c_funptr) :: finalize = c_null_funptr       ! may be null
        type(c_funptr) :: evaluate_point = c_null_funptr ! required
        type(c_funptr) :: evaluate_batch = c_null_funptr ! may be null
    end type seam_plugin_descriptor

    ! The procedures a descriptor points to (SeamInitFn, SeamFinalizeFn, ...).
    abstract interface
        function seam_init_fn(input, instance, message) bind(c) result(status)
            import :: seam_instance_in, c_ptr, c_char, c_int32_t, SEAM_MESSAGE_LEN
            type(seam_instance_in), intent(in) :: input
            type(c_ptr), intent(out) :: instance
            character(kind=c_char), intent(inout) :: message(SEAM_MESSAGE_LEN)
            integer(c_int32_t) :: status
        end function seam_init_fn

        subroutine seam_finalize_fn(instance) bind(c)
            import :: c_ptr
            type(c_ptr), value :: instance
        end subroutine seam_finalize_fn

        subroutine seam_evaluate_point_fn(instance, input, output) bind(c)
            import :: c_ptr, seam_point_in, seam_point_out
            type(c_ptr), value :: instance
            type(seam_point_in), intent(in) :: input
            type(seam_point_out), intent(inout) :: output
        end subroutine seam_evaluate_point_fn

        subroutine seam_evaluate_batch_fn(instance, input, output, n) bind(c)
            import :: c_ptr, seam_point_in, seam_point_out, c_size_t
            type(c_ptr), value :: instance
            integer(c_size_t), value :: n
            type(seam_point_in), intent(in) :: input(n)
            type(seam_point_out), intent(inout) :: output(n)
        end subroutine seam_evaluate_batch_fn
    end interface

    public :: seam_init_fn, seam_finalize_fn, seam_evaluate_point_fn, seam_evaluate_batch_fn
    public :: seam_set_message, seam_integer_data, seam_real_data, seam_c_string

    ! What seam_integer_data and seam_real_data point to when there is no data.
    integer(c_int64_t), target :: no_integers(0)
    real(c_double), target :: no_reals(0)

contains

    ! Write `text` into a C message buffer, cut to fit and NUL-terminated.
    subroutine seam_set_message(buffer, text)
        character(kind=c_char), intent(inout) :: buffer(SEAM_MESSAGE_LEN)
        character(len=*), intent(in) :: text
        integer :: i, n
        n = min(len(text), SEAM_MESSAGE_LEN - 1)
        do i = 1, n
            buffer(i) = text(i:i)
        end do
        buffer(n + 1) = c_null_char
    end subroutine seam_set_message

    ! The Integer Data behind `data` (n values) as a Fortran array (empty for n = 0).
    function seam_integer_data(data, n) result(values)
        type(c_ptr), intent(in) :: data
        integer(c_size_t), intent(in) :: n
        integer(c_int64_t), pointer :: values(:)
        if (n == 0 .or. .not. c_associated(data)) then
            values => no_integers
        else
            call c_f_pointer(data, values, [n])
        end if
    end function seam_integer_data

    ! The Real Data behind `data` (n values) as a Fortran array (empty for n = 0).
    function seam_real_data(data, n) result(values)
        type(c_ptr), intent(in) :: data
        integer(c_size_t), intent(in) :: n
        real(c_double), pointer :: values(:)
        if (n == 0 .or. .not. c_associated(data)) then
            values => no_reals
        else
            call c_f_pointer(data, values, [n])
        end if
    end function seam_real_data

    ! A NUL-terminated C string (at most `max_len` characters) as a Fortran string.
    function seam_c_string(text, max_len) result(out)
        type(c_ptr), intent(in) :: text
        integer, intent(in) :: max_len
        character(len=:), allocatable :: out
        character(kind=c_char), pointer :: chars(:)
        integer :: n
        out = ""
        if (.not. c_associated(text)) return
        call c_f_pointer(text, chars, [max_len])
        n = 0
        do while (n < max_len)
            if (chars(n + 1) == c_null_char) exit
            n = n + 1
        end do
        allocate (character(len=n) :: out)
        out = transfer(chars(1:n), out)
    end function seam_c_string

end module seam_plugin
