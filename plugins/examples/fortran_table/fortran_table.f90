! fortran_table: a gap conductance tabulated in one variable, as a seam plugin in Fortran.
!
! Integer Data = v, the variable the table is in:
!     1  contact pressure (Pa)
!     2  mean interface temperature (T_A + T_B)/2 (K)
!     3  gap (m)
! Real Data = x0 h0 x1 h1 ... (x strictly increasing, conductances h >= 0, W/m^2/K).
!
! Between points h is interpolated linearly; beyond the ends it is flat (the end value).
! Derivatives are exact: dh/dx is the slope of the segment holding x (at a table point the
! segment to its right; 0 outside the table), given as d_pressure, as d_temp_a = d_temp_b =
! dh/dx / 2, or as d_gap. With v = 1 it is the C example c_table to the last bit.
!
! The table itself is looked up by table_lookup, a plain Fortran routine that knows nothing
! of seam, as an existing user subroutine would be; the bind(c) procedures below only carry
! seam's arguments to it and its answer back (docs/plugins.md, "Writing a plugin in Fortran").
!
! Build: gfortran -std=f2008 -Wall -Wextra -Werror -O2 -shared -fPIC \
!            ../../include/seam_plugin.f90 fortran_table.f90 -o libseam_fortran_table.so
module fortran_table
    use, intrinsic :: iso_c_binding, only: c_int32_t, c_int64_t, c_size_t, c_double, &
        c_char, c_ptr, c_null_ptr, c_null_char, c_loc, c_funloc, c_f_pointer, c_associated
    use seam_plugin
    implicit none
    private
    public :: seam_plugin_v1

    integer, parameter :: by_pressure = 1, by_temperature = 2, by_gap = 3

    ! One instance: the table of one enforcement.
    type :: table
        integer :: variable
        real(c_double), allocatable :: x(:), h(:)
    end type table

    type(seam_plugin_descriptor), target, save :: descriptor
    character(kind=c_char, len=14), target, save :: name = "fortran_table" // c_null_char
    character(kind=c_char, len=6), target, save :: version = "1.0.0" // c_null_char

contains

    ! h and dh/dx at x for the table (xs, hs) of n points: an ordinary Fortran routine.
    pure subroutine table_lookup(n, xs, hs, x, h, dh)
        integer, intent(in) :: n
        real(c_double), intent(in) :: xs(n), hs(n), x
        real(c_double), intent(out) :: h, dh
        integer :: lo, hi, mid
        if (n == 1 .or. x < xs(1)) then
            h = hs(1)
            dh = 0
            return
        end if
        if (x >= xs(n)) then
            h = hs(n)
            dh = 0
            return
        end if
        lo = 1
        hi = n
        do while (hi - lo > 1)
            mid = lo + (hi - lo) / 2
            if (x >= xs(mid)) then
                lo = mid
            else
                hi = mid
            end if
        end do
        dh = (hs(lo + 1) - hs(lo)) / (xs(lo + 1) - xs(lo))
        h = hs(lo) + dh * (x - xs(lo))
    end subroutine table_lookup

    function table_init(input, instance, message) bind(c) result(status)
        type(seam_instance_in), intent(in) :: input
        type(c_ptr), intent(out) :: instance
        character(kind=c_char), intent(inout) :: message(SEAM_MESSAGE_LEN)
        integer(c_int32_t) :: status
        integer(c_int64_t), pointer :: ints(:)
        real(c_double), pointer :: reals(:)
        type(table), pointer :: t
        character(len=SEAM_MESSAGE_LEN) :: text
        integer :: i, n
        ints => seam_integer_data(input%integer_data, input%n_integer)
        reals => seam_real_data(input%real_data, input%n_real)
        status = SEAM_STATUS_ERROR
        instance = c_null_ptr
        if (size(ints) /= 1) then
            write (text, '(a, i0, a)') "fortran_table needs one Integer Data value, the variable " // &
                "(1 pressure, 2 mean temperature, 3 gap), got ", size(ints), " values"
            call seam_set_message(message, trim(text))
            return
        end if
        if (ints(1) < by_pressure .or. ints(1) > by_gap) then
            write (text, '(a, i0, a)') "fortran_table: Integer Data ", ints(1), &
                " is no variable (1 pressure, 2 mean temperature, 3 gap)"
            call seam_set_message(message, trim(text))
            return
        end if
        if (size(reals) < 2 .or. mod(size(reals), 2) /= 0) then
            write (text, '(a, i0, a)') "fortran_table needs Real Data as pairs x0 h0 x1 h1 ..., got ", &
                size(reals), " values"
            call seam_set_message(message, trim(text))
            return
        end if
        n = size(reals) / 2
        do i = 1, n
            if (i > 1) then
                if (.not. reals(2 * i - 1) > reals(2 * i - 3)) then
                    write (text, '(a, i0, a, g0)') "fortran_table: x must increase strictly (pair ", &
                        i - 1, ": ", reals(2 * i - 1)
                    call seam_set_message(message, trim(text))
                    return
                end if
            end if
            if (.not. reals(2 * i) >= 0) then
                write (text, '(a, i0, a, g0, a)') "fortran_table: conductance of pair ", i - 1, " is ", &
                    reals(2 * i), ", must be >= 0"
                call seam_set_message(message, trim(text))
                return
            end if
        end do
        allocate (t)
        t%variable = int(ints(1))
        t%x = reals(1::2)
        t%h = reals(2::2)
        instance = c_loc(t)
        status = SEAM_STATUS_OK
    end function table_init

    subroutine table_finalize(instance) bind(c)
        type(c_ptr), value :: instance
        type(table), pointer :: t
        if (.not. c_associated(instance)) return
        call c_f_pointer(instance, t)
        deallocate (t)
    end subroutine table_finalize

    subroutine table_point(instance, input, output) bind(c)
        type(c_ptr), value :: instance
        type(seam_point_in), intent(in) :: input
        type(seam_point_out), intent(inout) :: output
        type(table), pointer :: t
        real(c_double) :: x, h, dh
        if (.not. c_associated(instance)) then
            output%status = SEAM_STATUS_ERROR
            call seam_set_message(output%message, "fortran_table: no instance")
            return
        end if
        call c_f_pointer(instance, t)
        select case (t%variable)
        case (by_pressure)
            x = input%pressure
        case (by_temperature)
            x = 0.5_c_double * (input%temp_a + input%temp_b)
        case default
            x = input%gap
        end select
        call table_lookup(size(t%x), t%x, t%h, x, h, dh)
        output%status = SEAM_STATUS_OK
        output%value = h
        output%d_temp_a = 0
        output%d_temp_b = 0
        output%d_gap = 0
        output%d_pressure = 0
        select case (t%variable)
        case (by_pressure)
            output%d_pressure = dh
        case (by_temperature)
            output%d_temp_a = 0.5_c_double * dh
            output%d_temp_b = 0.5_c_double * dh
        case default
            output%d_gap = dh
        end select
    end subroutine table_point

    subroutine table_batch(instance, input, output, n) bind(c)
        type(c_ptr), value :: instance
        integer(c_size_t), value :: n
        type(seam_point_in), intent(in) :: input(n)
        type(seam_point_out), intent(inout) :: output(n)
        integer(c_size_t) :: i
        do i = 1, n
            call table_point(instance, input(i), output(i))
        end do
    end subroutine table_batch

    ! The entry point seam looks for: the descriptor, filled at the first call (c_funloc
    ! cannot appear in an initialisation).
    function seam_plugin_v1() bind(c, name="seam_plugin_v1") result(d)
        type(c_ptr) :: d
        descriptor%abi_major = SEAM_PLUGIN_ABI_MAJOR
        descriptor%abi_minor = SEAM_PLUGIN_ABI_MINOR
        descriptor%struct_size = int(storage_size(descriptor) / 8, c_int32_t)
        descriptor%state_size = 0
        descriptor%name = c_loc(name)
        descriptor%model_version = c_loc(version)
        descriptor%capabilities = ior(SEAM_CAP_THREAD_SAFE, SEAM_CAP_PROVIDES_DERIVATIVES)
        descriptor%init = c_funloc(table_init)
        descriptor%finalize = c_funloc(table_finalize)
        descriptor%evaluate_point = c_funloc(table_point)
        descriptor%evaluate_batch = c_funloc(table_batch)
        d = c_loc(descriptor)
    end function seam_plugin_v1

end module fortran_table
