/*
 * abi_layout.c: every size, field offset and constant of seam_plugin.h, one per line.
 * abi_layout.f90 prints the same lines from the Fortran module seam_plugin; the test
 * fortran_module_matches_the_c_header (tests/it/fortran_plugin.rs) compares the two.
 */
#include "seam_plugin.h"

#include <stddef.h>
#include <stdio.h>

#define FIELD(type, field) printf("%s %s %lu\n", #type, #field, (unsigned long)offsetof(type, field))
#define SIZE(type) printf("%s size %lu\n", #type, (unsigned long)sizeof(type))
#define CONSTANT(name) printf("%s %llu\n", #name, (unsigned long long)(name))

int main(void) {
    SIZE(SeamInstanceIn);
    FIELD(SeamInstanceIn, struct_size);
    FIELD(SeamInstanceIn, reserved);
    FIELD(SeamInstanceIn, model);
    FIELD(SeamInstanceIn, integer_data);
    FIELD(SeamInstanceIn, n_integer);
    FIELD(SeamInstanceIn, real_data);
    FIELD(SeamInstanceIn, n_real);
    SIZE(SeamPointIn);
    FIELD(SeamPointIn, struct_size);
    FIELD(SeamPointIn, reserved);
    FIELD(SeamPointIn, gap);
    FIELD(SeamPointIn, pressure);
    FIELD(SeamPointIn, temp_a);
    FIELD(SeamPointIn, temp_b);
    FIELD(SeamPointIn, x);
    FIELD(SeamPointIn, normal_a);
    FIELD(SeamPointIn, normal_b);
    FIELD(SeamPointIn, weight);
    FIELD(SeamPointIn, time);
    FIELD(SeamPointIn, dt);
    FIELD(SeamPointIn, step);
    FIELD(SeamPointIn, iteration);
    FIELD(SeamPointIn, surface_a);
    FIELD(SeamPointIn, surface_b);
    FIELD(SeamPointIn, fields);
    FIELD(SeamPointIn, n_fields);
    FIELD(SeamPointIn, integer_data);
    FIELD(SeamPointIn, n_integer);
    FIELD(SeamPointIn, real_data);
    FIELD(SeamPointIn, n_real);
    FIELD(SeamPointIn, state_old);
    FIELD(SeamPointIn, state_new);
    FIELD(SeamPointIn, n_state);
    SIZE(SeamPointOut);
    FIELD(SeamPointOut, struct_size);
    FIELD(SeamPointOut, status);
    FIELD(SeamPointOut, value);
    FIELD(SeamPointOut, d_temp_a);
    FIELD(SeamPointOut, d_temp_b);
    FIELD(SeamPointOut, d_gap);
    FIELD(SeamPointOut, d_pressure);
    FIELD(SeamPointOut, cutback_factor);
    FIELD(SeamPointOut, message);
    SIZE(SeamPluginDescriptor);
    FIELD(SeamPluginDescriptor, abi_major);
    FIELD(SeamPluginDescriptor, abi_minor);
    FIELD(SeamPluginDescriptor, struct_size);
    FIELD(SeamPluginDescriptor, state_size);
    FIELD(SeamPluginDescriptor, name);
    FIELD(SeamPluginDescriptor, model_version);
    FIELD(SeamPluginDescriptor, capabilities);
    FIELD(SeamPluginDescriptor, init);
    FIELD(SeamPluginDescriptor, finalize);
    FIELD(SeamPluginDescriptor, evaluate_point);
    FIELD(SeamPluginDescriptor, evaluate_batch);
    CONSTANT(SEAM_PLUGIN_ABI_MAJOR);
    CONSTANT(SEAM_PLUGIN_ABI_MINOR);
    CONSTANT(SEAM_MESSAGE_LEN);
    CONSTANT(SEAM_STATUS_OK);
    CONSTANT(SEAM_STATUS_ERROR);
    CONSTANT(SEAM_STATUS_CUTBACK);
    CONSTANT(SEAM_CAP_THREAD_SAFE);
    CONSTANT(SEAM_CAP_PROVIDES_DERIVATIVES);
    CONSTANT(SEAM_CAP_RETURNS_FLUX);
    CONSTANT(SEAM_CAP_HAS_STATE);
    CONSTANT(SEAM_CAP_ALL);
    printf("SEAM_PLUGIN_ENTRY_SYMBOL %s\n", SEAM_PLUGIN_ENTRY_SYMBOL);
    return 0;
}
