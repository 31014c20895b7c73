"""Cam program, pressure angle and profile."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.threshold.cam import Follower, FollowerProgram, curvature_radius, cycloidal, profile


def test_cycloidal_closed_form():
    y, dy = cycloidal(np.array([0.0, 0.25, 0.5, 0.75, 1.0, -1.0, 2.0]))
    assert y[:5] == pytest.approx([0, 0.25 - 1 / (2 * np.pi), 0.5, 0.75 + 1 / (2 * np.pi), 1])
    assert y[5] == 0 and y[6] == 1
    assert dy[:5] == pytest.approx([0, 1, 2, 1, 0])


def test_program_derivative_matches_finite_differences():
    prog = FollowerProgram(((0.1, 0.5), (0.9, 1.2), (1.5, 1.6)))
    phi = np.linspace(0, 2, 20001)
    y, dy = prog.evaluate(phi)
    assert np.abs(np.gradient(y, phi) - dy)[1:-1].max() < 1e-3 * dy.max()
    assert y[0] == 0 and y[13000] == pytest.approx(0.0) and y[-1] == pytest.approx(1.0)
    assert prog(np.array([0.7]))[0] == pytest.approx(1.0)


@pytest.mark.parametrize("primed", [False, True])
@pytest.mark.parametrize("orientation", [1, -1])
def test_pressure_angle_against_the_pitch_curve(primed, orientation):
    # Independent route: differentiate the pitch curve numerically in the cam frame, rotate the
    # tangent back, and measure its angle to the arm (the roller's path is normal to the arm).
    fol = Follower((0.3, -0.2), 0.4, 1.0, 0.2, np.radians(36.43), 0.05, primed)
    prog = FollowerProgram(((0.2, 0.6),))
    phi = np.linspace(0.0, 0.8, 4001)
    body = 0.7 + orientation * phi
    pitch = fol.pitch_curve(phi, prog, body)
    tan_cam = np.gradient(pitch, phi, axis=0)
    c, s = np.cos(body), np.sin(body)
    tan = np.stack([c * tan_cam[:, 0] - s * tan_cam[:, 1], s * tan_cam[:, 0] + c * tan_cam[:, 1]],
                   -1)
    arm = fol.roller_centre(prog(phi)) - fol.pivot
    cosang = np.abs((tan * arm).sum(1)) / np.hypot(*tan.T) / np.hypot(*arm.T)
    ref = np.degrees(np.arccos(np.clip(cosang, 0, 1)))
    got = fol.pressure_angle(phi, prog, orientation)
    assert np.abs(got - ref)[2:-2].max() < 0.05
    # at mid swing in a dwell the arm is square to KH: no pressure angle
    flat = Follower((0, 0), 0.0, 1.0, 0.2, 0.0, 0.05, primed)
    assert flat.pressure_angle(np.array([0.0]), FollowerProgram(()), orientation)[0] < 1e-9


def test_follower_output_sense():
    fol = Follower((0, 0), 0.0, 1.0, 0.3, np.radians(36.0), 0.05, False)
    # rising follower (outward) turns the crank clockwise about Z: output 0 -> 1
    assert fol.crank_angle(1.0) < fol.crank_angle(0.0)
    assert fol.roller_centre(1.0)[0] > fol.roller_centre(0.0)[0]
    alt = Follower((0, 0), 0.0, 1.0, 0.3, np.radians(36.0), 0.05, True)
    assert alt.output(1.0) == 0.0 and alt.crank_angle(0.0) < alt.crank_angle(1.0)
    # "0" -> "1" is clockwise for Z' too: output rises as y falls, angle falls
    assert alt.crank_angle(1.0 - 1.0) < alt.crank_angle(1.0 - 0.0)


def test_profile_offsets_by_roller_radius_and_circle_curvature():
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    circle = np.stack([2 * np.cos(t), 2 * np.sin(t)], -1)
    prof = profile(circle, 0.25)
    assert np.hypot(*prof.T) == pytest.approx(1.75)
    assert curvature_radius(circle) == pytest.approx(2.0, rel=1e-4)
