"""Neimark-Sacker bifurcations of Krack & Gross's two-DOF example by shooting, to round-off.

The system of NLvib's example `twoDOFoscillator_cubicSpring` (Krack & Gross, Harmonic Balance
for Nonlinear Vibration Problems, Springer 2019): masses 1 and 0.05, springs 1 (ground-1) and
0.0453 (1-2), dampers 0.002 and 0.013 on them, cubic springs 1 on x1 and 0.0042 on x1 - x2,
0.11 cos(Om t) on x1. The example places each bifurcation halfway between the two points of
its shooting continuation where the leading Floquet multiplier crosses the unit circle; this
script locates the same crossings to round-off instead: periodic orbits by Newton on the
shooting residual, the monodromy matrix from the variational equations (DOP853, rtol 1e-12),
natural continuation in Om from 0.8 rad/s, and bisection in Om where max |mu| crosses 1.

Usage: python3 nlvib_neimark_sacker.py   (needs numpy and scipy)
"""
import numpy as np
from scipy.integrate import solve_ivp

M = np.diag([1.0, 0.05])
K = np.array([[1.0453, -0.0453], [-0.0453, 0.0453]])
D = np.array([[0.015, -0.013], [-0.013, 0.013]])
MINV = np.linalg.inv(M)
F = np.array([0.11, 0.0])


def rhs(t, z, om):
    x, v = z[0:2], z[2:4]
    r = x[0] - x[1]
    fnl = np.array([x[0] ** 3 + 0.0042 * r**3, -0.0042 * r**3])
    a = MINV @ (F * np.cos(om * t) - D @ v - K @ x - fnl)
    # Variational equations: Phi' = A(t) Phi, A = [[0, I], [-M^-1 (K + K_nl(x)), -M^-1 D]].
    knl = np.array([[3 * x[0] ** 2 + 3 * 0.0042 * r**2, -3 * 0.0042 * r**2],
                    [-3 * 0.0042 * r**2, 3 * 0.0042 * r**2]])
    A = np.zeros((4, 4))
    A[0:2, 2:4] = np.eye(2)
    A[2:4, 0:2] = -MINV @ (K + knl)
    A[2:4, 2:4] = -MINV @ D
    phi = z[4:].reshape(4, 4)
    return np.concatenate([v, a, (A @ phi).ravel()])


def flow(y0, om):
    period = 2 * np.pi / om
    z0 = np.concatenate([y0, np.eye(4).ravel()])
    sol = solve_ivp(rhs, (0.0, period), z0, args=(om,), method="DOP853", rtol=1e-12, atol=1e-14)
    z = sol.y[:, -1]
    return z[0:4], z[4:].reshape(4, 4)


def periodic(y, om):
    for _ in range(30):
        yT, mono = flow(y, om)
        r = yT - y
        step = np.linalg.solve(mono - np.eye(4), -r)
        y = y + step
        if np.linalg.norm(step) < 1e-13 * (1 + np.linalg.norm(y)):
            break
    yT, mono = flow(y, om)
    return y, np.linalg.eigvals(mono)


def leading(mu):
    return mu[np.argmax(np.abs(mu))]


def main():
    om = 0.8
    # Linear response at the start, as the example's initial guess.
    q = np.linalg.solve(-om**2 * M + 1j * om * D + K, F)
    y = np.concatenate([q.real, -om * q.imag])
    y, mu = periodic(y, om)
    found = []
    step = 0.004
    while om < 1.2 and len(found) < 2:
        om_next = om + step
        y_next, mu_next = periodic(y, om_next)
        if (abs(leading(mu)) - 1) * (abs(leading(mu_next)) - 1) < 0:
            a, b, ya = om, om_next, y
            for _ in range(60):
                c = 0.5 * (a + b)
                yc, muc = periodic(ya, c)
                if (abs(leading(muc)) - 1) * (abs(leading(mu)) - 1) > 0:
                    a, ya = c, yc
                else:
                    b = c
                if b - a < 1e-12:
                    break
            lead = leading(muc)
            found.append((0.5 * (a + b), lead))
            print(f"Neimark-Sacker at {0.5 * (a + b):.9f} rad/s, multiplier {lead:.9f} (angle {np.angle(lead):.6f} rad)")
        om, y, mu = om_next, y_next, mu_next


if __name__ == "__main__":
    main()
