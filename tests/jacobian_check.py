"""The rate-and-state slab equations' Jacobian by central differences (for the tests of the analytic one)."""

import numpy as np


def central_differences(dynamics, state, rate):
    """d(dy/dt)/dy of ``dynamics.rhs`` at ``state`` [3 m + 1] by central differences, float64 [3 m + 1, 3 m + 1].

    Steps: 1e-7 mm for the slips, 1e-9 for the friction coefficients, 1e-6 of the value (at least 1e-9) for the states
    and the lever rotation (m = 3 interfaces).
    """
    numeric = np.empty((state.size, state.size))
    for j in range(state.size):
        step = 1e-7 if j < 3 else (1e-9 if j < 6 else 1e-6 * max(abs(state[j]), 1e-3))
        up, down = state.copy(), state.copy()
        up[j] += step
        down[j] -= step
        numeric[:, j] = (dynamics.rhs(up, rate) - dynamics.rhs(down, rate)) / (2 * step)
    return numeric
