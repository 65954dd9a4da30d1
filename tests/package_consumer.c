/* A program outside rpr3gen that uses one generated variant as a package (tests/
 * test_c_package.py builds it with CMake's find_package, with add_subdirectory and with
 * pkg-config).
 *
 * Reads the parameter vector as "name value" lines (`rpr3gen params`) on stdin, in the header's
 * order, evaluates the inverse dynamics at one sample and prints "VARIANT SOURCE_HASH STATUS",
 * then "name value" per output (%.17g); with EXPECTED_SOURCE_HASH defined (by the CMake project,
 * from the package's configuration) one more line says whether it is the header's.
 */
#include <stdio.h>
#include <string.h>

#include "rpr3.h"

int main(void)
{
    double params[RPR3_NUM_PARAMS];
    double out[RPR3_NUM_OUTPUTS];
    const double q[3] = {0.01, -0.02, 0.1};
    const double qd[3] = {0.1, 0.2, -0.3};
    const double qdd[3] = {1.0, -0.5, 2.0};
    char name[64];
    int k, status;

    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        if (scanf("%63s %lf", name, &params[k]) != 2 || strcmp(name, rpr3_param_names[k]) != 0) {
            fprintf(stderr, "parameter %d: expected %s\n", k, rpr3_param_names[k]);
            return 4;
        }
    }
    status = rpr3_inverse_dynamics(params, q, qd, qdd, out);
    printf("%s %s %d\n", RPR3_VARIANT, RPR3_SOURCE_HASH, status);
    for (k = 0; k < RPR3_NUM_OUTPUTS; ++k) {
        printf("%s %.17g\n", rpr3_output_names[k], out[k]);
    }
#ifdef EXPECTED_SOURCE_HASH
    printf("package source hash %s\n",
           strcmp(EXPECTED_SOURCE_HASH, RPR3_SOURCE_HASH) == 0 ? "matches" : "differs");
#endif
    return status;
}
