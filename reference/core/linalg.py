"""Small dense linear systems (at most three contacts at once), without allocation."""

from .jit import hot


@hot
def solve_small(A, r, m, out):
    """out[:m] = A[:m, :m]⁻¹ r[:m] for m ≤ 3 (Cramer's rule for m ≤ 2, elimination with
    partial pivoting for 3, which overwrites A and r: callers pass systems they rebuild
    before each solve).  Returns False when the system is singular."""
    if m == 0:
        return True
    if m == 1:
        if A[0, 0] == 0.0:
            return False
        out[0] = r[0] / A[0, 0]
        return True
    if m == 2:
        return _solve_2(A, r, out)
    return _solve_3(A, r, out)


@hot
def _solve_2(A, r, out):
    """Cramer's rule for a 2 × 2 system."""
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    if det == 0.0:
        return False
    out[0] = (r[0] * A[1, 1] - r[1] * A[0, 1]) / det
    out[1] = (r[1] * A[0, 0] - r[0] * A[1, 0]) / det
    return True


@hot
def _solve_3(M, v, out):
    """Gaussian elimination with partial pivoting for a 3 × 3 system M x = v, in place,
    then back substitution."""
    for c in range(3):
        p = c
        for i in range(c + 1, 3):
            if abs(M[i, c]) > abs(M[p, c]):
                p = i
        if M[p, c] == 0.0:
            return False
        if p != c:
            for j in range(3):
                M[c, j], M[p, j] = M[p, j], M[c, j]
            v[c], v[p] = v[p], v[c]
        for i in range(c + 1, 3):
            f = M[i, c] / M[c, c]
            for j in range(c, 3):
                M[i, j] -= f * M[c, j]
            v[i] -= f * v[c]
    for i in range(2, -1, -1):
        s = v[i]
        for j in range(i + 1, 3):
            s -= M[i, j] * out[j]
        out[i] = s / M[i, i]
    return True
