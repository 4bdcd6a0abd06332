"""Independent reference for the seed 002 example: closed-form crank-slider kinematics and a
direct Newton-Euler solve of the three links, written without any kinetostat code.

Crank angle phi from top dead centre, clockwise; slider axis vertical through O.
"""
from __future__ import annotations

import numpy as np

r, l, n_rpm = 0.036, 0.11, 4500.0
w1 = n_rpm * np.pi / 30
g = 9.81
m2, m3, I2 = 4.9 / g, 3.8 / g, 0.0017
F_gas = np.pi * 0.08**2 / 4 * 0.8 * 2.4e6      # N, at 30 deg, downwards on the piston


def cr(a: np.ndarray, b: np.ndarray) -> float:
    """z-component of a x b for 2-vectors."""
    return a[0] * b[1] - a[1] * b[0]


def kinematics(phi_deg: float) -> dict[str, np.ndarray | float]:
    f = np.radians(phi_deg)
    s, c = np.sin(f), np.cos(f)
    k = np.sqrt(l**2 - r**2 * s**2)
    A = np.array([r * s, r * c])
    dA, ddA = np.array([r * c, -r * s]), np.array([-r * s, -r * c])          # d/dphi, d2/dphi2
    y = r * c + k
    dy = -r * s - r**2 * s * c / k
    ddy = -r * c - r**2 * (c**2 - s**2) / k - r**4 * s**2 * c**2 / k**3
    B = np.array([0.0, y])
    vA, aA = dA * w1, ddA * w1**2
    vB, aB = np.array([0.0, dy * w1]), np.array([0.0, ddy * w1**2])
    # rod angle from +x: theta2 = atan2(y - r c, -r s); omega2 from v_B - v_A = w2 x (B - A)
    AB = B - A
    w2 = cr(AB, vB - vA) / (AB @ AB)
    rel = aB - aA + w2**2 * AB
    e2 = cr(AB, rel) / (AB @ AB)
    return dict(A=A, B=B, S2=(A + B) / 2, vA=vA, vB=vB, vS2=(vA + vB) / 2, aA=aA, aB=aB,
                aS2=(aA + aB) / 2, w2=w2, e2=e2)


def newton_euler(phi_deg: float) -> dict[str, float | np.ndarray]:
    """Unknowns x = [R12x, R12y, R32x, R32y, R43x, M_bal] (massless crank, slider guide vertical)."""
    kn = kinematics(phi_deg)
    A, B, S = kn["A"], kn["B"], kn["S2"]
    M, b = np.zeros((6, 6)), np.zeros(6)
    # rod: R12 + R32 - m2 g y = m2 aS2 ; moment about S2 = I2 e2
    M[0, [0, 2]] = 1
    b[0] = m2 * kn["aS2"][0]
    M[1, [1, 3]] = 1
    b[1] = m2 * kn["aS2"][1] + m2 * g
    dA, dB = A - S, B - S
    M[2, :4] = [-dA[1], dA[0], -dB[1], dB[0]]
    b[2] = I2 * kn["e2"]
    # piston: -R32 + R43 (horizontal) - m3 g y - F_gas y = m3 aB
    M[3, 2], M[3, 4] = -1, 1
    b[3] = m3 * kn["aB"][0]
    M[4, 3] = -1
    b[4] = m3 * kn["aB"][1] + m3 * g + F_gas
    # crank (massless): R01 = R12 ; M_bal + A x (-R12) = 0
    M[5, 5], M[5, 0], M[5, 1] = 1, A[1], -A[0]
    x = np.linalg.solve(M, b)
    return dict(R12=x[0:2], R32=x[2:4], R43=np.array([x[4], 0.0]), M_bal=x[5],
                Fi2=-m2 * kn["aS2"], Fi3=-m3 * kn["aB"], Mi2=-I2 * kn["e2"])
