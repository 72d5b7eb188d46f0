/* Shared by the pm tests (test_photon_map.c, test_photons.c): checks,
 * the noise scale of CDL_TEST_SCALE and the tests' own random numbers. */
#ifndef CDL_TEST_PM_COMMON_H
#define CDL_TEST_PM_COMMON_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "core/error.h"
#include "core/vec.h"
#include "test_util.h" /* CHECK, die_on */


#define PI_D 3.14159265358979323846

static double tol_scale = 1.0;   /* noise tolerances x sqrt(CDL_TEST_SCALE) */
static uint32_t count_div = 1;   /* photon counts / CDL_TEST_SCALE */

static inline void test_scale_init(void)
{
    if (getenv("CDL_TEST_SCALE") && atoi(getenv("CDL_TEST_SCALE")) > 1) {
        count_div = (uint32_t)atoi(getenv("CDL_TEST_SCALE"));
        tol_scale = sqrt((double)count_div);
    }
}

static inline double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* splitmix64: the test's own random numbers */
static uint64_t rng_state = 0x9e3779b97f4a7c15ULL;
static inline double rnd(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static inline cdl_vec3 rnd_dir(void)
{
    double z = 1.0 - 2.0 * rnd(), phi = 2.0 * PI_D * rnd(), r = sqrt(fmax(0.0, 1.0 - z * z));
    return cdl_v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
}

static inline double angle_deg(cdl_vec3 a, cdl_vec3 b)
{
    /* atan2 of |a x b| and a.b in double: accurate for tiny angles */
    double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z;
    double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz) * 180.0 / PI_D;
}


static const char *const kernel_name[] = {"box", "cone", "epanechnikov"};

#endif
