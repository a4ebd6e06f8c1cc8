/* dyadfmu: a program outside the project using the installed core.
 *
 * Solves the slider of a slider-crank (an RRT dyad at rest: the gas force on the
 * slider, the rod a two-force member) and checks the reactions against their
 * closed form and the equilibrium of the whole dyad. Built by tests/consumer/
 * CMakeLists.txt (find_package or add_subdirectory) and by pkg-config alone;
 * scripts/tests/test_install.py drives all three.
 *
 * Usage: consumer double|float   (the scalar the program must have been built with)
 * Exits 0 when every check holds, 1 otherwise.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dyadfmu/dyad.h"
#include "dyadfmu/vec2.h"

#define GAS_FORCE 8000.0
#define ROD_ANGLE 0.2

static int check(const char* what, double got, double want, double tolerance)
{
    if (fabs(got - want) <= tolerance * GAS_FORCE) {
        return 0;
    }
    fprintf(stderr, "consumer: %s is %.9g, expected %.9g\n", what, got, want);
    return 1;
}

int main(int argc, char** argv)
{
    const int is_float = sizeof(dyad_real) == sizeof(float);
    const double tolerance = is_float ? 1e-5 : 1e-12;
    const double normal = GAS_FORCE * tan(ROD_ANGLE);
    dyad_input in = dyad_input_default();
    dyad_result out;
    dyad_status status;
    int failures = 0;

    if (argc != 2 || strcmp(argv[1], is_float ? "float" : "double") != 0) {
        fprintf(stderr, "consumer: built with dyad_real = %s, asked for %s\n",
                is_float ? "float" : "double", argc == 2 ? argv[1] : "(nothing)");
        return 1;
    }
    in.guide_k = dyad_vec2_make(1, 0);
    in.m.length = 0;
    in.m.mass = (dyad_real)0.45;
    in.m.force = dyad_vec2_make((dyad_real)-GAS_FORCE, 0);
    in.n.dir = dyad_dir_from_angle((dyad_real)ROD_ANGLE);
    in.n.length = (dyad_real)0.2;
    status = dyad_solve(DYAD_RRT, &in, &out);
    if (status != DYAD_STATUS_OK) {
        fprintf(stderr, "consumer: dyad_solve: %s (%s)\n", dyad_status_name(status),
                dyad_field_name(out.field));
        return 1;
    }
    /* The rod carries the gas force along itself; the guide takes its normal part. */
    failures += check("R_np.x", out.r_np.x, GAS_FORCE, tolerance);
    failures += check("R_np.y", out.r_np.y, normal, tolerance);
    failures += check("R_mk.x", out.r_mk.x, 0, tolerance);
    failures += check("R_mk.y", out.r_mk.y, -normal, tolerance);
    failures += check("N_mk", out.n_mk, -normal, tolerance);
    /* Whole dyad at rest: the two external reactions balance the load. */
    failures += check("sum of x forces", out.r_mk.x + out.r_np.x + in.m.force.x, 0, tolerance);
    failures += check("sum of y forces", out.r_mk.y + out.r_np.y + in.m.force.y, 0, tolerance);
    printf("consumer (%s): R_mk = (%g, %g) N, R_np = (%g, %g) N: %s\n", argv[1], out.r_mk.x,
           out.r_mk.y, out.r_np.x, out.r_np.y, failures == 0 ? "ok" : "FAILED");
    return failures == 0 ? 0 : 1;
}
