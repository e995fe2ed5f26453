component smtcal_robot_model "The robot of smtcal's measurement scenarios (tests/linuxcnc-sim/README.md): where it really is for a command, and what its measuring devices read";

description """
Runs in the servo thread after the motion controller. The robot's real
position departs from the command by a known smooth error field (a constant,
a linear part and four sinusoids per axis; z a tilt) and by backlash (a play
operator per axis: the nut lags the command by up to half the backlash).
measure_model.py holds the same model in Python; both must agree.

x-latched, y-latched: the real position when the latch input fell (the
vacuum valve going off: where a part was placed).

Devices (param device: 0 none, 1 transducer, 2 probe):
- transducer: the paper's plate with grooves carried by the robot; the
  measuring transducer on a flank reads the compression (contact-z minus the
  plate's real z) plus zero plus slope times the real position's distance
  from the nearest groove node along ldt-axis; the reference reads the
  compression; both 0 (at rest) without contact. Gaussian noise ldt-noise.
- probe: a touch probe in a hole plate (holes on a lattice of hole-pitch
  from hole-x0, hole-y0, turned by hole-angle radians about that hole):
  contact while the stylus is below plate-z and its real centre is at
  least the contact radius (plus Gaussian noise probe-noise, drawn anew
  after every contact) from the nearest hole's centre. Setting the
  parameters while the program runs moves the plate (a bump).
""";

pin in float x_cmd;
pin in float y_cmd;
pin in float z_cmd;
pin out float x_real;
pin out float y_real;
pin out float z_real;
pin in bit latch;
pin out float x_latched;
pin out float y_latched;

param rw float dx_c;
param rw float dx_gx;
param rw float dx_gy;
param rw float dx_amp_#[4];
param rw float dx_kx_#[4];
param rw float dx_ky_#[4];
param rw float dx_ph_#[4];
param rw float dy_c;
param rw float dy_gx;
param rw float dy_gy;
param rw float dy_amp_#[4];
param rw float dy_kx_#[4];
param rw float dy_ky_#[4];
param rw float dy_ph_#[4];
param rw float dz_c;
param rw float dz_gx;
param rw float dz_gy;
param rw float backlash_x;
param rw float backlash_y;

param rw unsigned device;
param rw unsigned ldt_axis;
param rw float ldt_origin;
param rw float ldt_pitch = 5;
param rw float ldt_slope = 1;
param rw float ldt_zero;
param rw float ldt_contact_z;
param rw float ldt_noise;
pin out float ldt_measure;
pin out float ldt_reference;

param rw float hole_x0;
param rw float hole_y0;
param rw float hole_angle;
param rw float hole_pitch = 5;
param rw float hole_radius = 2;
param rw float plate_z;
param rw float probe_noise;
pin out bit probe_contact;

param rw unsigned seed = 1994;

variable double nut_x;
variable double nut_y;
variable int started;
variable rtapi_u64 rng;
variable double threshold;
variable int latch_was;

function _ fp;
license "GPL";
;;

#include <rtapi_math.h>

static double uniform01(rtapi_u64 *state) {
    /* xorshift64* */
    rtapi_u64 x = *state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *state = x;
    return ((x * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

static double normal(rtapi_u64 *state) {
    double u1 = uniform01(state), u2 = uniform01(state);
    if (u1 < 1e-300) u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

static double play(double nut, double cmd, double backlash) {
    double half = 0.5 * backlash;
    if (cmd - nut > half) return cmd - half;
    if (cmd - nut < -half) return cmd + half;
    return nut;
}

static double nearest(double v, double origin, double pitch) {
    return origin + pitch * rint((v - origin) / pitch);
}

FUNCTION(_) {
    int k;
    double mx, my, ex, ey;
    if (!started) {
        nut_x = x_cmd;
        nut_y = y_cmd;
        rng = 0x9E3779B97F4A7C15ULL ^ (rtapi_u64)seed;
        threshold = hole_radius;
        started = 1;
    }
    nut_x = play(nut_x, x_cmd, backlash_x);
    nut_y = play(nut_y, y_cmd, backlash_y);
    mx = nut_x;
    my = nut_y;
    ex = dx_c + dx_gx * mx + dx_gy * my;
    ey = dy_c + dy_gx * mx + dy_gy * my;
    for (k = 0; k < 4; k++) {
        ex += dx_amp(k) * sin(dx_kx(k) * mx + dx_ky(k) * my + dx_ph(k));
        ey += dy_amp(k) * sin(dy_kx(k) * mx + dy_ky(k) * my + dy_ph(k));
    }
    x_real = mx + ex;
    y_real = my + ey;
    z_real = z_cmd + dz_c + dz_gx * mx + dz_gy * my;
    /* Where the robot really was when latch fell (the vacuum valve off: a Place). */
    if (latch_was && !latch) {
        x_latched = x_real;
        y_latched = y_real;
    }
    latch_was = latch;

    if (device == 1) {
        double compression = ldt_contact_z - z_real;
        if (compression > 0) {
            double along = ldt_axis == 1 ? y_real : x_real;
            double d = along - nearest(along, ldt_origin, ldt_pitch);
            ldt_reference = compression + ldt_noise * normal(&rng);
            ldt_measure = compression + ldt_zero + ldt_slope * d + ldt_noise * normal(&rng);
        } else {
            ldt_reference = 0;
            ldt_measure = 0;
        }
    } else {
        ldt_reference = 0;
        ldt_measure = 0;
    }

    if (device == 2) {
        /* The stylus in the plate's frame (turned by hole_angle about its first hole). */
        double dx = x_real - hole_x0, dy = y_real - hole_y0;
        double c = cos(hole_angle), s = sin(hole_angle);
        double px = c * dx + s * dy, py = -s * dx + c * dy;
        double hx = nearest(px, 0, hole_pitch);
        double hy = nearest(py, 0, hole_pitch);
        double r = sqrt((px - hx) * (px - hx) + (py - hy) * (py - hy));
        int contact = z_real < plate_z && r >= threshold;
        if (probe_contact && !contact) threshold = hole_radius + probe_noise * normal(&rng);
        probe_contact = contact;
    } else {
        probe_contact = 0;
    }
}
