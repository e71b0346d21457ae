/*
 * Compiled floor for a four-bar's cycle analysis: the arithmetic of
 * balancer.cycle.cycle_analysis (Newton-Euler route) in a plain C loop, one thread.
 *
 * For N equally spaced crank angles theta1 = 2*pi*j/N at constant speed w (alpha1 = 0):
 *   positions      Meijaard & van der Wijk (2020) Eq. 2-4 (l23, d23, h23, l2 = (d23 + i h23) l23/|l23|)
 *   velocities     Eq. 6-7 (transfer functions Theta2, Theta3)
 *   accelerations  Eq. 9-10
 *   Newton-Euler   per link, with the applied force F_k at its centre of mass and moment M_k:
 *                  the coupler-rocker joint force F23 from the moments of link 3 about A3 and
 *                  of link 2 about A1 (a 2x2 solve), then F12, F01, F43 from the force
 *                  balances, the driving torque from link 1's moments about A0;
 *   outputs        R_A0, R_A3 (forces of the mechanism on the ground), shaking force
 *                  R_A0 + R_A3, shaking moment about A0 (R_A3's moment, the motor's reaction
 *                  -tau and the counter-rotors' 2*J*alpha), driving torque tau.
 * Eight doubles per angle are written to a preallocated array, as balancer writes its arrays.
 *
 * Usage: floor_fourbar N OUT|- l1 l2 l3 l4 branch w  then per link (crank, coupler, rocker)
 *        m I e f Fx Fy M, then Jc1 Jc3 (counter-rotor inertias).  29 numbers in all.
 * Prints the seconds of allocation + loop (clock_gettime, monotonic); with OUT not "-"
 * writes the N x 8 doubles (RA0x RA0y RA3x RA3y SFx SFy SM tau) to OUT for checking.
 *
 * Build: cc -O2 -o floor_fourbar floor_fourbar.c -lm
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

int main(int argc, char **argv) {
    if (argc != 32) {
        fprintf(stderr, "usage: %s N OUT l1 l2 l3 l4 branch w (m I e f Fx Fy M)x3 Jc1 Jc3\n",
                argv[0]);
        return 2;
    }
    long n = atol(argv[1]);
    const char *out_path = argv[2];
    double p[29];
    for (int k = 0; k < 29; k++) p[k] = atof(argv[3 + k]);
    const double l1 = p[0], l2 = p[1], l3 = p[2], l4 = p[3], sign = p[4], w = p[5];
    double m[3], in[3], e[3], f[3], fx[3], fy[3], mo[3];
    for (int k = 0; k < 3; k++) {
        m[k] = p[6 + 7 * k]; in[k] = p[7 + 7 * k]; e[k] = p[8 + 7 * k]; f[k] = p[9 + 7 * k];
        fx[k] = p[10 + 7 * k]; fy[k] = p[11 + 7 * k]; mo[k] = p[12 + 7 * k];
    }
    const double jc1 = p[27], jc3 = p[28];
    (void)jc1; /* alpha1 = 0: the crank's counter-rotor adds nothing at constant speed */
    const double len[3] = {l1, l2, l3};

    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    double *res = malloc((size_t)n * 8 * sizeof(double));
    if (!res) { fprintf(stderr, "out of memory\n"); return 1; }
    const double step = 2.0 * M_PI / (double)n;
    const double w2c = w * w;
    for (long j = 0; j < n; j++) {
        const double th = step * (double)j;
        /* Eq. 2-4 */
        const double c = cos(th), s = sin(th);
        const double v1x = l1 * c, v1y = l1 * s;
        const double v23x = l4 - v1x, v23y = -v1y; /* l23 = -l1 - l4, l4 = -l4 (theta4 = pi) */
        const double l23 = sqrt(v23x * v23x + v23y * v23y);
        const double d23 = (l23 * l23 + l2 * l2 - l3 * l3) / (2.0 * l23);
        const double h23 = sign * sqrt(l2 * l2 - d23 * d23);
        const double ux = v23x / l23, uy = v23y / l23;
        const double v2x = d23 * ux - h23 * uy, v2y = d23 * uy + h23 * ux;
        const double v3x = v23x - v2x, v3y = v23y - v2y;
        /* Eq. 6-7: Theta2 = -<l3, i l1>/<l3, i l2> = -cross(l3, l1)/cross(l3, l2) */
        const double c32 = cross(v3x, v3y, v2x, v2y);
        const double th2 = -cross(v3x, v3y, v1x, v1y) / c32;
        const double th3 = -cross(v2x, v2y, v1x, v1y) / (-c32);
        const double w2 = th2 * w, w3 = th3 * w;
        /* Eq. 9-10 with alpha1 = 0 (<x, i y> = -cross(x, y)) */
        const double a2 = ((v3x * v1x + v3y * v1y) * w2c + (v3x * v2x + v3y * v2y) * w2 * w2
                           + l3 * l3 * w3 * w3) / (-c32);
        const double a3 = ((v2x * v1x + v2y * v1y) * w2c + l2 * l2 * w2 * w2
                           + (v2x * v3x + v2y * v3y) * w3 * w3) / c32;
        /* centres of mass relative to each link's first joint: r_k = s_k * l_k / |l_k| */
        const double vx[3] = {v1x, v2x, v3x}, vy[3] = {v1y, v2y, v3y};
        double rx[3], ry[3];
        for (int k = 0; k < 3; k++) {
            const double cx = vx[k] / len[k], cy = vy[k] / len[k];
            rx[k] = e[k] * cx - f[k] * cy;
            ry[k] = e[k] * cy + f[k] * cx;
        }
        /* accelerations (alpha1 = 0): a = (i alpha - omega^2) r */
        const double aA1x = -w2c * v1x, aA1y = -w2c * v1y;
        const double aA2x = aA1x - a2 * v2y - w2 * w2 * v2x, aA2y = aA1y + a2 * v2x - w2 * w2 * v2y;
        const double ag1x = -w2c * rx[0], ag1y = -w2c * ry[0];
        const double ag2x = aA1x - a2 * ry[1] - w2 * w2 * rx[1];
        const double ag2y = aA1y + a2 * rx[1] - w2 * w2 * ry[1];
        const double ag3x = aA2x - a3 * ry[2] - w3 * w3 * rx[2];
        const double ag3y = aA2y + a3 * rx[2] - w3 * w3 * ry[2];
        /* D_k = m_k a_k - F_k: the force the joints must supply */
        const double d1x = m[0] * ag1x - fx[0], d1y = m[0] * ag1y - fy[0];
        const double d2x = m[1] * ag2x - fx[1], d2y = m[1] * ag2y - fy[1];
        const double d3x = m[2] * ag3x - fx[2], d3y = m[2] * ag3y - fy[2];
        /* rocker about A3: (A2 - A3) x F23 = I3 a3 + Jc3 a3 - M3 + (G3 - A3) x D3
         * coupler about A1: (A2 - A1) x F23 = -(I2 a2 - M2 + (G2 - A1) x D2)
         * (a counter-rotor on the rocker acts on it as the couple -Jc3 a3) */
        const double g3a3x = rx[2] - v3x, g3a3y = ry[2] - v3y; /* G3 - A3 = r3 - l3 */
        const double b1 = (in[2] + jc3) * a3 - mo[2] + cross(g3a3x, g3a3y, d3x, d3y);
        const double b2 = -(in[1] * a2 - mo[1] + cross(rx[1], ry[1], d2x, d2y));
        /* (-l3) x F = b1, l2 x F = b2: [[l3y, -l3x], [-l2y, l2x]] F = [b1, b2] */
        const double det = v3y * v2x - v3x * v2y; /* = -cross(l3, l2) */
        const double f23x = (b1 * v2x + v3x * b2) / det;
        const double f23y = (v3y * b2 + v2y * b1) / det;
        const double f43x = d3x - f23x, f43y = d3y - f23y;
        const double f12x = d2x + f23x, f12y = d2y + f23y;
        const double f01x = d1x + f12x, f01y = d1y + f12y;
        /* crank about A0: tau = I1 a1 - M1 + r1 x D1 + l1 x F12, a1 = 0 */
        const double tau = -mo[0] + cross(rx[0], ry[0], d1x, d1y) + cross(v1x, v1y, f12x, f12y);
        double *o = res + 8 * j;
        o[0] = -f01x; o[1] = -f01y;               /* R_A0: mechanism on ground */
        o[2] = -f43x; o[3] = -f43y;               /* R_A3 */
        o[4] = o[0] + o[2]; o[5] = o[1] + o[3];   /* shaking force */
        o[6] = l4 * o[3] - tau + 2.0 * jc3 * a3;  /* moment about A0: A3 = (l4, 0) */
        o[7] = tau;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double checksum = 0.0;
    for (long j = 0; j < n; j++) checksum += res[8 * j + 6];
    printf("%.9f %.17g\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec), checksum);
    if (out_path[0] != '-' || out_path[1] != '\0') {
        FILE *fp = fopen(out_path, "wb");
        if (!fp || fwrite(res, sizeof(double), (size_t)n * 8, fp) != (size_t)n * 8) {
            fprintf(stderr, "cannot write %s\n", out_path);
            return 1;
        }
        fclose(fp);
    }
    free(res);
    return 0;
}
