#!/usr/bin/python3
# measure_model.py - the simulated robot of the measurement scenarios, in
# Python: the same model as smtcal_robot_model.comp (the HAL component that
# runs in LinuxCNC's servo thread), for setting its parameters and for
# judging what was measured. Both must agree; run_measure.py checks the
# component against this file at a few points before it measures.
#
# The robot's real position for a command c: the nut of each axis lags the
# command by up to half the backlash (a play operator), m; then
# real = m + field(m). The field is a smooth, paper-like error: per axis a
# constant, a linear part (a scale error and an out-of-squareness) and four
# sinusoids with wavelengths of 180 to 600 mm; |error| stays under 0.2 mm
# over the paper cell's regions. z: a tilt (the transducer's reference
# transducer takes it out).
import math

TWO_PI = 2 * math.pi

# (amplitude mm, wavelength along x mm (0: none), wavelength along y mm, phase rad)
FIELD = {
    "x": {"c": -0.06, "gx": 0.00035, "gy": -0.00020,
          "waves": [(0.045, 260.0, 0.0, 0.4), (0.030, 0.0, 210.0, 1.1), (0.020, 380.0, 300.0, 2.3),
                    (0.012, 180.0, -450.0, 0.7)]},
    "y": {"c": 0.02, "gx": -0.00025, "gy": 0.00030,
          "waves": [(0.040, 0.0, 240.0, 0.9), (0.028, 300.0, 0.0, 2.0), (0.018, 420.0, -350.0, 0.3),
                    (0.010, -200.0, 600.0, 1.7)]},
    "z": {"c": 0.01, "gx": 0.00008, "gy": -0.00005},
}
BACKLASH = {"x": 0.012, "y": 0.008}  # mm


def wavenumber(wavelength):
    return 0.0 if wavelength == 0 else TWO_PI / wavelength


def field(axis, x, y):
    """The error of the real position along `axis` at the nut position (x, y)."""
    f = FIELD[axis]
    e = f["c"] + f["gx"] * x + f["gy"] * y
    for amp, lx, ly, phase in f.get("waves", []):
        e += amp * math.sin(wavenumber(lx) * x + wavenumber(ly) * y + phase)
    return e


def approached_error(x, y, approach):
    """The robot's error at the command (x, y) reached by the final approach
    `approach` (x, y mm): the nut lags by half the backlash against the
    approach's direction on each axis."""
    mx = x - math.copysign(BACKLASH["x"] / 2, approach[0])
    my = y - math.copysign(BACKLASH["y"] / 2, approach[1])
    return (mx + field("x", mx, my) - x, my + field("y", mx, my) - y)


def hal_params(component="smtcal-robot-model.0"):
    """setp commands that give the HAL component this model."""
    lines = []
    for axis in ("x", "y"):
        f = FIELD[axis]
        lines += [f"setp {component}.d{axis}-c {f['c']!r}", f"setp {component}.d{axis}-gx {f['gx']!r}",
                  f"setp {component}.d{axis}-gy {f['gy']!r}"]
        for k, (amp, lx, ly, phase) in enumerate(f["waves"]):
            lines += [f"setp {component}.d{axis}-amp-{k} {amp!r}",
                      f"setp {component}.d{axis}-kx-{k} {wavenumber(lx)!r}",
                      f"setp {component}.d{axis}-ky-{k} {wavenumber(ly)!r}",
                      f"setp {component}.d{axis}-ph-{k} {phase!r}"]
        lines.append(f"setp {component}.backlash-{axis} {BACKLASH[axis]!r}")
    z = FIELD["z"]
    lines += [f"setp {component}.dz-c {z['c']!r}", f"setp {component}.dz-gx {z['gx']!r}",
              f"setp {component}.dz-gy {z['gy']!r}"]
    return lines
