/*
 * Test plugin without derivatives: h = 1 + p^2 + T_A T_B + exp(-gap). The host must form
 * the derivatives by finite differences; the test compares them with
 * dh/dp = 2p, dh/dT_A = T_B, dh/dT_B = T_A, dh/dgap = -exp(-gap).
 */
#include "seam_plugin.h"

#include <math.h>

static void smooth_point(void *instance, const SeamPointIn *in, SeamPointOut *out) {
    (void)instance;
    out->status = SEAM_STATUS_OK;
    out->value = 1.0 + in->pressure * in->pressure + in->temp_a * in->temp_b + exp(-in->gap);
}

static const SeamPluginDescriptor DESCRIPTOR = {
    SEAM_PLUGIN_ABI_MAJOR, SEAM_PLUGIN_ABI_MINOR, (uint32_t)sizeof(SeamPluginDescriptor), 0,
    "smooth", "0.0.1", SEAM_CAP_THREAD_SAFE, NULL, NULL, smooth_point, NULL,
};

const SeamPluginDescriptor *seam_plugin_v1(void) { return &DESCRIPTOR; }
