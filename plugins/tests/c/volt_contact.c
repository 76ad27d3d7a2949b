/*
 * Test plugin: an electrical contact conductance that depends on the voltage of side A,
 * read from the point's fields, which at an electrical contact are (V_A, V_B):
 *   h = real_data[0] * (1 + real_data[1] * fields[0])
 * Without the two fields (a thermal contact) it fails with a message. No derivatives
 * (the host differentiates), thread-safe, no state.
 */
#include <stdio.h>

#include "seam_plugin.h"

static void volt_point(void *instance, const SeamPointIn *in, SeamPointOut *out) {
    (void)instance;
    if (in->n_fields != 2 || in->n_real < 2) {
        out->status = SEAM_STATUS_ERROR;
        snprintf(out->message, SEAM_MESSAGE_LEN,
                 "needs the voltages (V_A, V_B) as fields and real data h0 a, got %zu fields",
                 in->n_fields);
        return;
    }
    out->status = SEAM_STATUS_OK;
    out->value = in->real_data[0] * (1.0 + in->real_data[1] * in->fields[0]);
}

static const SeamPluginDescriptor DESCRIPTOR = {
    SEAM_PLUGIN_ABI_MAJOR, SEAM_PLUGIN_ABI_MINOR, (uint32_t)sizeof(SeamPluginDescriptor), 0,
    "volt_contact", "0.0.1", SEAM_CAP_THREAD_SAFE,
    NULL, NULL, volt_point, NULL,
};

const SeamPluginDescriptor *seam_plugin_v1(void) { return &DESCRIPTOR; }
