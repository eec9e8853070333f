"""Collision-time and reflection formulas against hand-worked cases."""

import math

import numpy as np
import pytest

from kicktimes.billiard.geometry import (
    boundary_hit_time,
    collide_elastic,
    collide_mirror,
    pair_hit_time,
    reflect,
    sin_theta_at,
)


def test_boundary_time_from_the_centre_is_the_radius_of_the_free_disk():
    assert boundary_hit_time(0.0, 0.0, 0.6, 0.8, 0.97) == pytest.approx(0.97, abs=1e-15)


@pytest.mark.parametrize(("x0", "vx", "expected"), [(0.5, 1.0, 0.47), (0.5, -1.0, 1.47)])
def test_boundary_time_on_a_diameter_with_radial_velocity(x0, vx, expected):
    assert boundary_hit_time(x0, 0.0, vx, 0.0, 0.97) == pytest.approx(expected, abs=1e-15)


def test_boundary_time_of_an_off_axis_chord():
    # centre at (0, 0.6) moving along +x reaches |x| = 1 at x = 0.8
    assert boundary_hit_time(0.0, 0.6, 1.0, 0.0, 1.0) == pytest.approx(0.8, abs=1e-15)


def test_boundary_time_scales_with_speed():
    assert boundary_hit_time(0.1, 0.2, 1.2, -1.6, 0.9) == pytest.approx(
        boundary_hit_time(0.1, 0.2, 0.6, -0.8, 0.9) / 2.0, rel=1e-14
    )


def test_boundary_time_from_the_wall_going_outward_is_zero():
    # a centre a hair outside (round-off) moving outward is reflected at once
    assert boundary_hit_time(0.9 + 1e-15, 0.0, 1.0, 0.0, 0.9) == 0.0


def test_boundary_time_from_the_wall_going_inward_is_the_chord():
    # from (rho, 0) with direction at angle a to the inward normal the chord is 2 rho cos a
    a = 0.3
    t = boundary_hit_time(0.9, 0.0, -math.cos(a), math.sin(a), 0.9)
    assert t == pytest.approx(2 * 0.9 * math.cos(a), rel=1e-14)


def test_head_on_pair_contact_time():
    # d = (1, 0), w = (-2, 0): |1 - 2t| = 0.2 first at t = 0.4
    assert pair_hit_time(1.0, 0.0, -2.0, 0.0, 0.2) == pytest.approx(0.4, abs=1e-15)


def test_separating_pair_never_collides():
    assert pair_hit_time(1.0, 0.0, 2.0, 0.0, 0.2) == math.inf


def test_near_grazing_pair_contact_hits_inside_and_misses_outside_the_cross_section():
    sigma = 0.04
    # relative motion along -x with impact parameter b: contact iff b < sigma
    t_hit = pair_hit_time(1.0, sigma * (1 - 1e-9), -1.0, 0.0, sigma)
    assert 1.0 - sigma < t_hit < 1.0
    # exact: 1 - sqrt(sigma^2 - b^2) = 1 - sigma sqrt(e (2 - e)) with b = sigma (1 - e); the
    # discriminant of a grazing contact is small, so allow 1e-10 absolute
    assert t_hit == pytest.approx(1.0 - sigma * math.sqrt(1e-9 * (2 - 1e-9)), abs=1e-10)
    assert pair_hit_time(1.0, sigma * (1 + 1e-9), -1.0, 0.0, sigma) == math.inf


def test_pair_starting_nearly_in_contact():
    sigma = 0.02
    t = pair_hit_time(sigma + 1e-13, 0.0, -2.0, 0.0, sigma)
    assert 0.0 <= t < 1e-12
    # overlapping by round-off and approaching: collide now
    assert pair_hit_time(sigma - 1e-15, 0.0, -2.0, 0.0, sigma) == 0.0


def test_pair_time_is_cancellation_free_for_tiny_gaps():
    # naive (-b - sqrt(b^2 - w^2 c)) / w^2 loses all digits here
    sigma = 0.02
    gap = 1e-10
    t = pair_hit_time(sigma + gap, 0.0, -1.0, 0.0, sigma)
    assert t == pytest.approx(gap, rel=1e-5)


def test_reflection_reverses_the_normal_component_and_keeps_the_tangential():
    vx, vy = reflect(0.6, 0.8, 1.0, 0.0)
    assert (vx, vy) == pytest.approx((-0.6, 0.8))


def test_mirror_rule_is_an_involution_and_keeps_speeds():
    rng = np.random.default_rng(3)
    for _ in range(100):
        a, b = rng.uniform(0, 2 * np.pi, 2)
        phi = rng.uniform(0, 2 * np.pi)
        n = (math.cos(phi), math.sin(phi))
        v = (math.cos(a), math.sin(a), math.cos(b), math.sin(b))
        once = collide_mirror(*v, *n)
        twice = collide_mirror(*once, *n)
        assert twice == pytest.approx(v, abs=1e-15)
        assert math.hypot(once[0], once[1]) == pytest.approx(1.0, abs=1e-15)
        assert math.hypot(once[2], once[3]) == pytest.approx(1.0, abs=1e-15)


def test_elastic_rule_conserves_energy_and_momentum_and_swaps_normal_components():
    v = (0.3, -0.7, -0.9, 0.2)
    n = (1.0, 0.0)
    out = collide_elastic(*v, *n)
    assert out == pytest.approx((-0.9, -0.7, 0.3, 0.2))
    assert sum(c * c for c in out) == pytest.approx(sum(c * c for c in v))
    assert out[0] + out[2] == pytest.approx(v[0] + v[2])
    assert out[1] + out[3] == pytest.approx(v[1] + v[3])


def test_sin_theta_is_the_ccw_tangential_component():
    rho = 0.98
    # at s = pi/2 the ccw tangent is (-1, 0)
    assert sin_theta_at(0.0, rho, -1.0, 0.0, rho) == pytest.approx(1.0)
    assert sin_theta_at(0.0, rho, 0.0, 1.0, rho) == pytest.approx(0.0)
    assert sin_theta_at(rho, 0.0, 0.6, -0.8, rho) == pytest.approx(-0.8)


def test_graze_leaves_the_wall_inward_at_the_grazing_angle_with_the_same_speed_and_sense():
    from kicktimes.billiard.geometry import GRAZE_ANGLE, graze

    rho = 0.9
    for phi in np.linspace(0, 2 * np.pi, 7):
        x, y = rho * math.cos(phi), rho * math.sin(phi)
        for sense in (1.0, -1.0):
            speed = 2.5
            vx, vy = -sense * speed * math.sin(phi), sense * speed * math.cos(phi)  # tangent
            wx, wy = graze(x, y, vx, vy, rho, speed)
            assert math.hypot(wx, wy) == pytest.approx(speed, rel=1e-15)
            # inward at angle GRAZE_ANGLE from the tangent: x.w / (rho |w|) = -sin(delta)
            assert (x * wx + y * wy) / (rho * speed) == pytest.approx(-math.sin(GRAZE_ANGLE),
                                                                       rel=1e-9)
            assert math.copysign(1.0, x * wy - y * wx) == sense
            # the chord is 2 rho sin(delta) long and ends on the wall
            t = boundary_hit_time(x, y, wx, wy, rho)
            assert t * speed == pytest.approx(2 * rho * math.sin(GRAZE_ANGLE), rel=1e-6)
