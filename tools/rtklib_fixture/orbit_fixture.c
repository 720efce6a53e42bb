/*
 * orbit_fixture.c - satellite positions and clocks of every ephemeris of a RINEX GPS
 * navigation file, computed by RTKLIB, as the reference for sdins's orbit code.
 *
 * RTKLIB version: 2.4.3 b34 (Debian bookworm packages rtklib / librtklib-dev
 * 2.4.3.b34+dfsg-1+b1). Debian ships the shared library without its header, so the
 * few types used are declared below from the documented 2.4.3 b34 API (gtime_t, eph_t,
 * the leading members of nav_t); nav_t, obs_t and sta_t are passed as large zeroed
 * buffers so that the members this program does not declare have room.
 *
 * Build and run (from the repository root):
 *   apt-get install -y rtklib librtklib-dev
 *   cc -O2 -o /tmp/orbit_fixture tools/rtklib_fixture/orbit_fixture.c -lRTKLib -lm
 *   /tmp/orbit_fixture ../shared/data/psins_gnss/abpo0080.15n \
 *       > crates/sdins-sim/tests/data/abpo_rtklib_orbits.csv
 *
 * Output: one row per ephemeris and time t = toe + dt, dt = -7200, -6000, ..., +7200 s
 * (every 20 min): prn, iode, toe (GPS week, s of week), dt, satellite ECEF position
 * (m) and clock bias (s) from RTKLIB's eph2pos. eph2pos's clock is
 * af0 + af1 (t - toc) + af2 (t - toc)^2 + relativistic term, WITHOUT T_GD; its
 * position is the IS-GPS-200 algorithm in the ECEF frame of t.
 */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct { time_t time; double sec; } gtime_t;

typedef struct { /* eph_t of RTKLIB 2.4.3 b34 */
    int sat, iode, iodc, sva, svh, week, code, flag;
    gtime_t toe, toc, ttr;
    double A, e, i0, OMG0, omg, M0, deln, OMGd, idot;
    double crc, crs, cuc, cus, cic, cis;
    double toes, fit, f0, f1, f2;
    double tgd[6];
    double Adot, ndot;
} eph_t;

typedef struct { /* leading members of nav_t of RTKLIB 2.4.3 b34 */
    int n, nmax, ng, ngmax, ns, nsmax, ne, nemax, nc, ncmax, na, namax, nt, ntmax;
    eph_t *eph;
} nav_head_t;

extern int readrnx(const char *file, int rcv, const char *opt, void *obs, void *nav, void *sta);
extern void eph2pos(gtime_t time, const eph_t *eph, double *rs, double *dts, double *var);
extern gtime_t timeadd(gtime_t t, double sec);
extern double time2gpst(gtime_t t, int *week);
extern int satsys(int sat, int *prn);

/* the library calls these application hooks (rnx2rtkp defines them too) */
int showmsg(const char *format, ...) { (void)format; return 0; }
void settspan(gtime_t ts, gtime_t te) { (void)ts; (void)te; }
void settime(gtime_t time) { (void)time; }

#define SYS_GPS 0x01
#define BUF_BYTES (64u << 20)

int main(int argc, char **argv)
{
    void *obs = calloc(1, BUF_BYTES), *nav = calloc(1, BUF_BYTES), *sta = calloc(1, BUF_BYTES);
    nav_head_t *nh = (nav_head_t *)nav;
    int i, k, prn, week;

    if (argc != 2 || !obs || !nav || !sta) {
        fprintf(stderr, "usage: orbit_fixture NAVFILE\n");
        return 2;
    }
    if (readrnx(argv[1], 1, "", obs, nav, sta) <= 0 || nh->n <= 0) {
        fprintf(stderr, "no ephemerides read from %s\n", argv[1]);
        return 1;
    }
    printf("prn,iode,toe_week,toe_sow_s,dt_s,x_m,y_m,z_m,clock_bias_s\n");
    for (i = 0; i < nh->n; i++) {
        const eph_t *eph = nh->eph + i;
        if (satsys(eph->sat, &prn) != SYS_GPS) continue;
        double toe_sow = time2gpst(eph->toe, &week);
        for (k = -6; k <= 6; k++) {
            double dt = 1200.0 * k, rs[3], dts, var;
            eph2pos(timeadd(eph->toe, dt), eph, rs, &dts, &var);
            printf("%d,%d,%d,%.3f,%.0f,%.5f,%.5f,%.5f,%.15e\n", prn, eph->iode, week, toe_sow,
                   dt, rs[0], rs[1], rs[2], dts);
        }
    }
    return 0;
}
