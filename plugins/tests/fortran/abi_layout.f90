! abi_layout.f90: every size, field offset and constant of the Fortran module seam_plugin,
! one per line, as abi_layout.c prints them from seam_plugin.h; the test
! fortran_module_matches_the_c_header (tests/it/fortran_plugin.rs) compares the two.
program abi_layout
    use, intrinsic :: iso_c_binding, only: c_loc, c_ptr, c_intptr_t, c_int64_t, c_sizeof
    use seam_plugin
    implicit none
    type(seam_instance_in), target :: inst
    type(seam_point_in), target :: pin
    type(seam_point_out), target :: pout
    type(seam_plugin_descriptor), target :: desc

    call size_line("SeamInstanceIn", int(c_sizeof(inst)))
    call field("SeamInstanceIn", "struct_size", c_loc(inst), c_loc(inst%struct_size))
    call field("SeamInstanceIn", "reserved", c_loc(inst), c_loc(inst%reserved))
    call field("SeamInstanceIn", "model", c_loc(inst), c_loc(inst%model))
    call field("SeamInstanceIn", "integer_data", c_loc(inst), c_loc(inst%integer_data))
    call field("SeamInstanceIn", "n_integer", c_loc(inst), c_loc(inst%n_integer))
    call field("SeamInstanceIn", "real_data", c_loc(inst), c_loc(inst%real_data))
    call field("SeamInstanceIn", "n_real", c_loc(inst), c_loc(inst%n_real))
    call size_line("SeamPointIn", int(c_sizeof(pin)))
    call field("SeamPointIn", "struct_size", c_loc(pin), c_loc(pin%struct_size))
    call field("SeamPointIn", "reserved", c_loc(pin), c_loc(pin%reserved))
    call field("SeamPointIn", "gap", c_loc(pin), c_loc(pin%gap))
    call field("SeamPointIn", "pressure", c_loc(pin), c_loc(pin%pressure))
    call field("SeamPointIn", "temp_a", c_loc(pin), c_loc(pin%temp_a))
    call field("SeamPointIn", "temp_b", c_loc(pin), c_loc(pin%temp_b))
    call field("SeamPointIn", "x", c_loc(pin), c_loc(pin%x(1)))
    call field("SeamPointIn", "normal_a", c_loc(pin), c_loc(pin%normal_a(1)))
    call field("SeamPointIn", "normal_b", c_loc(pin), c_loc(pin%normal_b(1)))
    call field("SeamPointIn", "weight", c_loc(pin), c_loc(pin%weight))
    call field("SeamPointIn", "time", c_loc(pin), c_loc(pin%time))
    call field("SeamPointIn", "dt", c_loc(pin), c_loc(pin%dt))
    call field("SeamPointIn", "step", c_loc(pin), c_loc(pin%step))
    call field("SeamPointIn", "iteration", c_loc(pin), c_loc(pin%iteration))
    call field("SeamPointIn", "surface_a", c_loc(pin), c_loc(pin%surface_a))
    call field("SeamPointIn", "surface_b", c_loc(pin), c_loc(pin%surface_b))
    call field("SeamPointIn", "fields", c_loc(pin), c_loc(pin%fields))
    call field("SeamPointIn", "n_fields", c_loc(pin), c_loc(pin%n_fields))
    call field("SeamPointIn", "integer_data", c_loc(pin), c_loc(pin%integer_data))
    call field("SeamPointIn", "n_integer", c_loc(pin), c_loc(pin%n_integer))
    call field("SeamPointIn", "real_data", c_loc(pin), c_loc(pin%real_data))
    call field("SeamPointIn", "n_real", c_loc(pin), c_loc(pin%n_real))
    call field("SeamPointIn", "state_old", c_loc(pin), c_loc(pin%state_old))
    call field("SeamPointIn", "state_new", c_loc(pin), c_loc(pin%state_new))
    call field("SeamPointIn", "n_state", c_loc(pin), c_loc(pin%n_state))
    call size_line("SeamPointOut", int(c_sizeof(pout)))
    call field("SeamPointOut", "struct_size", c_loc(pout), c_loc(pout%struct_size))
    call field("SeamPointOut", "status", c_loc(pout), c_loc(pout%status))
    call field("SeamPointOut", "value", c_loc(pout), c_loc(pout%value))
    call field("SeamPointOut", "d_temp_a", c_loc(pout), c_loc(pout%d_temp_a))
    call field("SeamPointOut", "d_temp_b", c_loc(pout), c_loc(pout%d_temp_b))
    call field("SeamPointOut", "d_gap", c_loc(pout), c_loc(pout%d_gap))
    call field("SeamPointOut", "d_pressure", c_loc(pout), c_loc(pout%d_pressure))
    call field("SeamPointOut", "cutback_factor", c_loc(pout), c_loc(pout%cutback_factor))
    call field("SeamPointOut", "message", c_loc(pout), c_loc(pout%message(1)))
    call size_line("SeamPluginDescriptor", int(c_sizeof(desc)))
    call field("SeamPluginDescriptor", "abi_major", c_loc(desc), c_loc(desc%abi_major))
    call field("SeamPluginDescriptor", "abi_minor", c_loc(desc), c_loc(desc%abi_minor))
    call field("SeamPluginDescriptor", "struct_size", c_loc(desc), c_loc(desc%struct_size))
    call field("SeamPluginDescriptor", "state_size", c_loc(desc), c_loc(desc%state_size))
    call field("SeamPluginDescriptor", "name", c_loc(desc), c_loc(desc%name))
    call field("SeamPluginDescriptor", "model_version", c_loc(desc), c_loc(desc%model_version))
    call field("SeamPluginDescriptor", "capabilities", c_loc(desc), c_loc(desc%capabilities))
    call field("SeamPluginDescriptor", "init", c_loc(desc), c_loc(desc%init))
    call field("SeamPluginDescriptor", "finalize", c_loc(desc), c_loc(desc%finalize))
    call field("SeamPluginDescriptor", "evaluate_point", c_loc(desc), c_loc(desc%evaluate_point))
    call field("SeamPluginDescriptor", "evaluate_batch", c_loc(desc), c_loc(desc%evaluate_batch))
    call constant("SEAM_PLUGIN_ABI_MAJOR", int(SEAM_PLUGIN_ABI_MAJOR, c_int64_t))
    call constant("SEAM_PLUGIN_ABI_MINOR", int(SEAM_PLUGIN_ABI_MINOR, c_int64_t))
    call constant("SEAM_MESSAGE_LEN", int(SEAM_MESSAGE_LEN, c_int64_t))
    call constant("SEAM_STATUS_OK", int(SEAM_STATUS_OK, c_int64_t))
    call constant("SEAM_STATUS_ERROR", int(SEAM_STATUS_ERROR, c_int64_t))
    call constant("SEAM_STATUS_CUTBACK", int(SEAM_STATUS_CUTBACK, c_int64_t))
    call constant("SEAM_CAP_THREAD_SAFE", int(SEAM_CAP_THREAD_SAFE, c_int64_t))
    call constant("SEAM_CAP_PROVIDES_DERIVATIVES", int(SEAM_CAP_PROVIDES_DERIVATIVES, c_int64_t))
    call constant("SEAM_CAP_RETURNS_FLUX", int(SEAM_CAP_RETURNS_FLUX, c_int64_t))
    call constant("SEAM_CAP_HAS_STATE", int(SEAM_CAP_HAS_STATE, c_int64_t))
    call constant("SEAM_CAP_ALL", int(SEAM_CAP_ALL, c_int64_t))
    print "(a, 1x, a)", "SEAM_PLUGIN_ENTRY_SYMBOL", SEAM_PLUGIN_ENTRY_SYMBOL

contains

    subroutine size_line(struct, bytes)
        character(len=*), intent(in) :: struct
        integer, intent(in) :: bytes
        print "(a, 1x, a, 1x, i0)", struct, "size", bytes
    end subroutine size_line

    subroutine field(struct, name, base, at)
        character(len=*), intent(in) :: struct, name
        type(c_ptr), intent(in) :: base, at
        print "(a, 1x, a, 1x, i0)", struct, name, &
            transfer(at, 0_c_intptr_t) - transfer(base, 0_c_intptr_t)
    end subroutine field

    subroutine constant(name, value)
        character(len=*), intent(in) :: name
        integer(c_int64_t), intent(in) :: value
        print "(a, 1x, i0)", name, value
    end subroutine constant

end program abi_layout
