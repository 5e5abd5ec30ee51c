"""Exact event-driven integration of the linearised model (compiled with numba).

Between events the acceleration a is constant (free flight, or contacts held by constant
forces), so a gap is the quadratic g + v s + ½ a_k s² and every event time is the first
positive root of one; roots are taken in cancellation-free form (`first_hit`).  Events:

- impact at an open contact reaching gap 0 while approaching: p⁺ = U_k p⁻.  A contact
  held at that moment must come out separating or resting (paper §2.3), otherwise the
  impact is undecidable, as are two contacts reached at once (status SIMULTANEOUS);
- accumulation of a chatter sequence (Zeno), completed in closed form (below);
- at every event the held set is re-solved: forces from F_B Θ⁻¹ F_Bᵀ η = g 1 over the
  subsets B of the closed contacts; the admissible one has η ≥ 0 and no closed contact
  with negative normal acceleration (an LCP by enumeration; rank(F) closed contacts is
  the end of the motion: every coordinate the contacts see is then 0).

Scaling.  The state is kept normalised with two exact powers of two, q = 2^kq q̃,
p = 2^kv p̃, t = 2^(kq−kv) t̃.  The normalised system is the same model with gravity
g̃ = 2^(kq−2kv) g (the scaling invariance of section 2.6 when kq = 2kv; with gravity
negligible, as in gravity-free chatter where gaps shrink faster than p²/g, the two
scales separate).  kv keeps the energy Ẽ = ½ p̃ᵀΘp̃ + m g̃ h̃ (true E = 4^kv Ẽ) in [½, 2),
kq keeps the gaps O(1).  Multiplying by powers of two costs no digits, so runs follow
the energy down any number of decades; intervals are stored as (t̃, kq − kv) and
absolute time as a double-double (t_hi + t_lo).

Chatter completion.  After an impact at contact j in free flight (0 < γ < 1), the gap of
j is a bouncing ball under gravity: its further impacts are at pre-velocities −γ^m v⁺ and
end after T = 2 v⁺ / (g (1 − γ)).  The impulses act along Θ⁻¹ f_j only, so the state at
the accumulation point is exactly the Θ-orthogonal projection of the free-flight state at
T onto f_jᵀq = f_jᵀp = 0 -- provided no other contact is reached within T, which is
checked with the bound gap_c(s) ≥ gap_c − s (|v_c| + g T + |f_cᵀΘ⁻¹f_j| Λ) (Λ = total
remaining impulse).  It is done once v⁺ ≤ `chatter_tol` × the velocity scale
V = √(2E max f Θ⁻¹ f).  When the last six impacts involve only one or two contacts S
and the normal speed is ≤ `decouple_tol` × V, the sequence is completed the same way --
projection onto the constraints of S of the free state after T -- with T from the
geometric decay of the recent intervals per decade of speed; this T is the only
approximation (it moves the state by about decouple_tol × (error of T)/T relative).  If
another contact is then at the ground within roundoff, the accumulation is undecidable.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

EPS = 2.220446049250313e-16

# event kinds
INITIAL, IMPACT, ACCUMULATION, END = 0, 1, 2, 3
# status codes (map to reference.trajectory.Status)
T_END, SINGULARITY, SIMULTANEOUS, MAX_IMPACTS, FAILED = 0, 1, 2, 3, 4
# integer columns
I_KIND, I_CONTACT, I_CONTACT2, I_KV, I_KQ, I_HELD1, I_HELD2, I_DTE = range(8)
N_ICOLS = 8
# float columns
F_DT, F_DTN, F_THI, F_TLO, F_IMPULSE, F_VPRE, F_VPOST, F_EPRE, F_EPOST, F_LOG2E = range(10)
N_FCOLS = 10
# state columns (normalised): q_pre, p_pre, q_post, p_post, acceleration that follows
N_SCOLS = 15
N_INFO = 8  # status, n_events, n_impacts, contact_a, contact_b, reason
RB = 64  # ring buffer of recent impacts


@njit(cache=True)
def first_hit(g, v, a):
    """First s > 0 with g + v s + a s²/2 = 0 reached while approaching (inf if none).
    g ≥ 0 is the gap now (g ≤ 0 is treated as touching), v its rate, a its acceleration.
    Roots are formed without cancellation: 2g/(√(v²−2ag) − v) for v ≤ 0, and
    (v + √(v²−2ag))/(−a) for v > 0 (a < 0)."""
    if g <= 0.0:
        if v > 0.0 and a < 0.0:
            return -2.0 * v / a
        return math.inf
    if a == 0.0:
        if v < 0.0:
            return g / -v
        return math.inf
    disc = v * v - 2.0 * a * g
    if a < 0.0:
        s = math.sqrt(disc)
        if v <= 0.0:
            if s - v == 0.0:  # v = 0 and a g below the smallest double: √(2g/|a|)
                return math.sqrt(2.0 * g / -a)
            return 2.0 * g / (s - v)
        return (v + s) / -a
    if v >= 0.0 or disc <= 0.0:
        return math.inf
    s = math.sqrt(disc)
    return 2.0 * g / (s - v)


@njit(cache=True)
def _two_sum(a, b):
    s = a + b
    bb = s - a
    err = (a - (s - bb)) + (b - bb)
    return s, err


@njit(cache=True)
def _add_time(t_hi, t_lo, dt):
    s, e = _two_sum(t_hi, dt)
    e += t_lo
    return _two_sum(s, e)


@njit(cache=True)
def _dot(F, c, x):
    return F[c, 0] * x[0] + F[c, 1] * x[1] + F[c, 2] * x[2]


@njit(cache=True)
def _tol(F, c, xs, floor):
    """Roundoff level of f_cᵀx: 64 ulps of the terms |f_ci| xs_i that formed it plus a
    floor at the motion's own scale."""
    return 64.0 * EPS * (abs(F[c, 0]) * xs[0] + abs(F[c, 1]) * xs[1] + abs(F[c, 2]) * xs[2] + floor)


@njit(cache=True)
def _w(F, tinv, a, b):
    return F[a, 0] * tinv[0] * F[b, 0] + F[a, 1] * tinv[1] * F[b, 1] + F[a, 2] * tinv[2] * F[b, 2]


@njit(cache=True)
def _project(x, F, tinv, idx, m):
    """In place: Θ-orthogonal projection of x onto {f_iᵀx = 0, i ∈ idx[:m]},
    x − Θ⁻¹F_Sᵀ (F_S Θ⁻¹ F_Sᵀ)⁻¹ F_S x (m ≤ 2 in closed form; m = 3 independent
    constraints leave x = 0)."""
    if m == 0:
        return
    if m >= 3:
        for i in range(3):
            x[i] = 0.0
        return
    i0 = idx[0]
    r0 = _dot(F, i0, x)
    if m == 1:
        lam0 = r0 / _w(F, tinv, i0, i0)
        for i in range(3):
            x[i] -= tinv[i] * F[i0, i] * lam0
        return
    i1 = idx[1]
    r1 = _dot(F, i1, x)
    a00, a01, a11 = _w(F, tinv, i0, i0), _w(F, tinv, i0, i1), _w(F, tinv, i1, i1)
    det = a00 * a11 - a01 * a01
    if det == 0.0:
        return
    lam0 = (a11 * r0 - a01 * r1) / det
    lam1 = (a00 * r1 - a01 * r0) / det
    for i in range(3):
        x[i] -= tinv[i] * (F[i0, i] * lam0 + F[i1, i] * lam1)


@njit(cache=True)
def _energy(q, p, thd, mass, g):
    """½ pᵀΘp + m g h."""
    return 0.5 * (thd[0] * p[0] * p[0] + thd[1] * p[1] * p[1] + thd[2] * p[2] * p[2]) + (
        mass * g * q[2]
    )


@njit(cache=True)
def _closed_indices(closed, nc, cidx):
    """The closed contacts' indices into cidx; returns how many."""
    ncl = 0
    for c in range(nc):
        if closed[c]:
            cidx[ncl] = c
            ncl += 1
    return ncl


@njit(cache=True)
def _held_solve(F, tinv, g, closed_idx, m, acc, held):
    """Admissible held subset B of the closed contacts (m ≤ 2): the LCP
    F_B Θ⁻¹ F_Bᵀ η = g 1, η ≥ 0, and no closed contact outside B with negative normal
    acceleration, solved by enumeration (both, then each alone, then none).  Writes the
    acceleration into acc and the held contacts (−1 padded) into held; returns their
    number, or −1 if no subset is admissible."""
    for i in range(3):
        held[i] = -1
    tol = 1e-12 * g
    if m == 2:
        i0, i1 = closed_idx[0], closed_idx[1]
        a00, a01, a11 = _w(F, tinv, i0, i0), _w(F, tinv, i0, i1), _w(F, tinv, i1, i1)
        det = a00 * a11 - a01 * a01
        if det != 0.0:
            e0 = g * (a11 - a01) / det
            e1 = g * (a00 - a01) / det
            if e0 >= -tol and e1 >= -tol:
                for i in range(3):
                    acc[i] = tinv[i] * (F[i0, i] * e0 + F[i1, i] * e1)
                acc[2] -= g
                held[0] = i0
                held[1] = i1
                return 2
        for k in range(2):
            ih, io = closed_idx[k], closed_idx[1 - k]
            e = g / _w(F, tinv, ih, ih)
            for i in range(3):
                acc[i] = tinv[i] * F[ih, i] * e
            acc[2] -= g
            if e >= -tol and _dot(F, io, acc) >= -tol:
                held[0] = ih
                return 1
    elif m == 1:
        ih = closed_idx[0]
        e = g / _w(F, tinv, ih, ih)
        for i in range(3):
            acc[i] = tinv[i] * F[ih, i] * e
        acc[2] -= g
        if e >= -tol:
            held[0] = ih
            return 1
    for i in range(3):
        acc[i] = 0.0
    acc[2] = -g
    for a in range(m):
        if _dot(F, closed_idx[a], acc) < -tol:
            return -1
    return 0


@njit(cache=True)
def _scale_q(F, q):
    s = 0.0
    for c in range(F.shape[0]):
        v = abs(F[c, 0] * q[0]) + abs(F[c, 1] * q[1]) + abs(F[c, 2] * q[2])
        if v > s:
            s = v
    return s


@njit(cache=True)
def _write_row(
    out_i, out_f, out_s, row, record, kind, c1, c2, kv, kq, held, dtn, t_hi, t_lo,
    imp, vpre, vpost, e_pre, e_post, q_pre, p_pre, q, p, acc,
):  # fmt: skip
    """One event row; normalised inputs, true values where the column says so."""
    out_i[row, I_KIND] = kind
    out_i[row, I_CONTACT] = c1
    out_i[row, I_CONTACT2] = c2
    out_i[row, I_KV] = kv
    out_i[row, I_KQ] = kq
    out_i[row, I_HELD1] = held[0]
    out_i[row, I_HELD2] = held[1]
    out_i[row, I_DTE] = kq - kv
    out_f[row, F_DTN] = dtn
    out_f[row, F_DT] = math.ldexp(dtn, kq - kv)
    out_f[row, F_THI] = t_hi
    out_f[row, F_TLO] = t_lo
    out_f[row, F_IMPULSE] = math.ldexp(imp, kv)
    out_f[row, F_VPRE] = math.ldexp(vpre, kv)
    out_f[row, F_VPOST] = math.ldexp(vpost, kv)
    out_f[row, F_EPRE] = e_pre
    out_f[row, F_EPOST] = e_post
    out_f[row, F_LOG2E] = math.log2(e_post) + 2 * kv if e_post > 0 else -math.inf
    if record:
        for i in range(3):
            out_s[row, i] = q_pre[i]
            out_s[row, 3 + i] = p_pre[i]
            out_s[row, 6 + i] = q[i]
            out_s[row, 9 + i] = p[i]
            out_s[row, 12 + i] = acc[i]


@njit(cache=True)
def _remaining_log2_time(rb_c, rb_ldt, rb_lu, pos, n):
    """log2 of the time still to come in a chatter sequence, from the recent impacts:
    with a the latest impact at least 10× faster than the last one and b the latest at
    least 100× faster, r = D(a→last)/D(b→a) and the rest is D(a→last) r/(1 − r)
    (geometric decay per decade of speed).  −inf when there is no estimate."""
    lu_last = rb_lu[pos]
    step = math.log2(10.0)
    ia = -1
    ib = -1
    for b in range(1, n):
        lu = rb_lu[(pos - b) % RB]
        if ia < 0 and lu >= lu_last + step:
            ia = b
        if ib < 0 and lu >= lu_last + 2.0 * step:
            ib = b
            break
    if ia < 0 or ib < 0:
        return -math.inf
    ref = rb_ldt[pos]
    d_a = 0.0
    for b in range(0, ia):
        d_a += math.exp2(rb_ldt[(pos - b) % RB] - ref)
    d_b = 0.0
    for b in range(ia, ib):
        d_b += math.exp2(rb_ldt[(pos - b) % RB] - ref)
    if not (d_b > 0.0):
        return -math.inf
    r = d_a / d_b
    if not (0.0 < r < 1.0):
        return -math.inf
    return math.log2(d_a * r / (1.0 - r)) + ref


@njit(cache=True)
def simulate_kernel(
    F,
    thd,
    mass,
    g,
    gamma,
    rank_f,
    q_init,
    p_init,
    t_end,
    max_impacts,
    log2_energy_floor,
    chatter_tol,
    decouple_tol,
    record_states,
    out_i,
    out_f,
    out_s,
    info,
):
    """Run the linear model from (q_init, p_init) at t = 0 (module docstring).

    One row per event in out_i (N, N_ICOLS), out_f (N, N_FCOLS) and, if record_states,
    out_s (N, N_SCOLS); info receives status, number of events and impacts, the contacts
    of an undecidable event and a reason code.  Stops (SINGULARITY) once log2 of the
    true energy falls below `log2_energy_floor`.  Returns the number of events."""
    nc = F.shape[0]
    cap = out_i.shape[0]
    tinv = 1.0 / thd
    w = np.zeros((nc, nc))
    for a in range(nc):
        for b in range(nc):
            w[a, b] = (
                F[a, 0] * tinv[0] * F[b, 0]
                + F[a, 1] * tinv[1] * F[b, 1]
                + F[a, 2] * tinv[2] * F[b, 2]
            )
    wmax = 0.0
    for a in range(nc):
        wmax = max(wmax, w[a, a])

    q = q_init.copy()
    p = p_init.copy()
    kv = 0
    kq = 0
    gt = g  # normalised gravity g 2^(kq − 2kv)
    info[:] = 0
    held = np.full(3, -1, dtype=np.int64)
    acc = np.zeros(3)
    acc[2] = -gt
    E = _energy(q, p, thd, mass, gt)
    if not (E > 0.0):
        _write_row(out_i, out_f, out_s, 0, record_states, INITIAL, -1, -1, 0, 0, held,
                   0.0, 0.0, 0.0, 0.0, 0.0, 0.0, E, E, q, p, q, p, acc)  # fmt: skip
        info[0] = SINGULARITY
        info[1] = 1
        info[5] = 3
        return 1

    # ------------------------------------------------------------ normalise (exact)
    sv = math.frexp(E)[1] // 2
    if sv != 0:
        for i in range(3):
            p[i] = math.ldexp(p[i], -sv)
        kv += sv
        gt = math.ldexp(gt, -2 * sv)
    lq = _scale_q(F, q)
    if lq > 0.0:
        sq = math.frexp(lq)[1]
        if sq != 0:
            for i in range(3):
                q[i] = math.ldexp(q[i], -sq)
            kq += sq
            gt = math.ldexp(gt, sq)
    qs = np.abs(q)
    ps = np.abs(p)
    t_hi = 0.0
    t_lo = 0.0
    closed = np.zeros(nc, dtype=np.bool_)
    acc[2] = -gt
    E = _energy(q, p, thd, mass, gt)
    _write_row(out_i, out_f, out_s, 0, record_states, INITIAL, -1, -1, kv, kq, held,
               0.0, 0.0, 0.0, 0.0, 0.0, 0.0, E, E, q, p, q, p, acc)  # fmt: skip
    n_ev = 1

    vfl = math.sqrt(2.0 * E * wmax)
    for c in range(nc):
        if _dot(F, c, q) <= _tol(F, c, qs, 0.0) and abs(_dot(F, c, p)) <= _tol(F, c, ps, vfl):
            closed[c] = True

    n_imp = 0
    pending_dtn = 0.0
    status = -1
    reason = 0
    rb_c = np.full(RB, -1, dtype=np.int64)
    rb_ldt = np.zeros(RB)
    rb_lu = np.zeros(RB)
    rb_pos = 0
    rb_n = 0
    cidx = np.zeros(nc + 3, dtype=np.int64)
    hidx = np.zeros(3, dtype=np.int64)
    sidx = np.zeros(3, dtype=np.int64)
    q_pre = np.zeros(3)
    p_pre = np.zeros(3)
    qn = np.zeros(3)
    pn = np.zeros(3)
    work = np.zeros(3)

    while True:
        E = _energy(q, p, thd, mass, gt)
        vfl = math.sqrt(2.0 * E * wmax)
        # ---------------------------------------------------------- impacts now?
        ncand = 0
        cand = -1
        cand2 = -1
        for c in range(nc):
            if closed[c]:
                continue
            if _dot(F, c, q) <= _tol(F, c, qs, 0.0) and _dot(F, c, p) < -_tol(F, c, ps, vfl):
                ncand += 1
                if cand < 0:
                    cand = c
                elif cand2 < 0:
                    cand2 = c
        if ncand >= 2:
            status = SIMULTANEOUS
            reason = 1
            info[3] = cand
            info[4] = cand2
            break
        if ncand == 1:
            if n_imp >= max_impacts or n_ev + 3 >= cap:
                status = MAX_IMPACTS
                break
            j = cand
            vpre = _dot(F, j, p)
            lam = -(1.0 + gamma) * vpre / w[j, j]
            for i in range(3):
                q_pre[i] = q[i]
                p_pre[i] = p[i]
            E_pre = E
            for i in range(3):
                p[i] += tinv[i] * F[j, i] * lam
            # the paper's rule for contacts held at the impact
            bad = -1
            for c in range(nc):
                if not closed[c]:
                    continue
                vc = _dot(F, c, p)
                for i in range(3):
                    work[i] = abs(p_pre[i]) + abs(p[i])
                tol = _tol(F, c, work, vfl)
                if vc < -tol:
                    bad = c
                elif vc > tol:
                    closed[c] = False
            if bad >= 0:
                for i in range(3):
                    p[i] = p_pre[i]  # report the state before the undecidable impact
                status = SIMULTANEOUS
                reason = 2
                info[3] = j
                info[4] = bad
                break
            if gamma == 0.0:
                closed[j] = True
            nh = 0
            for c in range(nc):
                if closed[c] and nh < 3:
                    hidx[nh] = c
                    nh += 1
            if nh > 0:
                _project(p, F, tinv, hidx, nh)
            vpost = -gamma * vpre if gamma > 0.0 else _dot(F, j, p)
            for i in range(3):
                ps[i] = abs(p_pre[i]) + abs(p[i])
            n_imp += 1
            E_post = _energy(q, p, thd, mass, gt)
            _write_row(out_i, out_f, out_s, n_ev, record_states, IMPACT, j, -1, kv, kq, held,
                       pending_dtn, t_hi, t_lo, lam, vpre, vpost, E_pre, E_post, q_pre, p_pre,
                       q, p, acc)  # fmt: skip
            # the interval before this impact was measured in the scales of the row
            n_ev += 1
            rb_pos = (rb_pos + 1) % RB
            rb_c[rb_pos] = j
            rb_ldt[rb_pos] = (math.log2(pending_dtn) if pending_dtn > 0 else -1e300) + (kq - kv)
            rb_lu[rb_pos] = (math.log2(abs(vpre)) if vpre != 0.0 else -1e300) + kv
            rb_n = min(rb_n + 1, RB)
            pending_dtn = 0.0

            # renormalise (exact)
            if E_post > 0.0:
                sv = math.frexp(E_post)[1] // 2
                if sv != 0:
                    for i in range(3):
                        p[i] = math.ldexp(p[i], -sv)
                        ps[i] = math.ldexp(ps[i], -sv)
                    kv += sv
                    gt = math.ldexp(gt, -2 * sv)
                    vpre = math.ldexp(vpre, -sv)
            lq = _scale_q(F, q)
            if lq > 0.0:
                sq = math.frexp(lq)[1]
                if sq > 4 or sq < -4:
                    for i in range(3):
                        q[i] = math.ldexp(q[i], -sq)
                        qs[i] = math.ldexp(qs[i], -sq)
                    kq += sq
                    gt = math.ldexp(gt, sq)
            E = _energy(q, p, thd, mass, gt)
            if not (E > 0.0):
                status = SINGULARITY
                reason = 3
                break
            if math.log2(E) + 2 * kv <= log2_energy_floor:
                status = SINGULARITY
                reason = 4
                break

            # ------------------------------------------ chatter completion
            any_closed = False
            for c in range(nc):
                if closed[c]:
                    any_closed = True
            if not (0.0 < gamma < 1.0) or any_closed:
                continue
            vplus = _dot(F, j, p)
            vel_scale = math.sqrt(2.0 * E * wmax)
            rem = math.inf
            if math.isfinite(t_end):
                rem = math.ldexp((t_end - t_hi) - t_lo, kv - kq)
            fall = gt * (1.0 - gamma)  # may underflow when gravity is negligible
            T = 2.0 * vplus / fall if fall > 0.0 else math.inf
            sidx[0] = j
            sidx[1] = -1
            m_s = 0
            exact = False
            if 0.0 < vplus <= chatter_tol * vel_scale and T < math.inf and T <= rem:
                # one contact, provably alone until its accumulation: exact
                lam_tot = (1.0 + gamma) * vplus / (w[j, j] * (1.0 - gamma))
                safe = True
                for c in range(nc):
                    if c == j:
                        continue
                    vmax = abs(_dot(F, c, p)) + gt * T + abs(w[c, j]) * lam_tot
                    if _dot(F, c, q) - T * vmax <= _tol(F, c, qs, 0.0):
                        safe = False
                if safe:
                    m_s = 1
                    exact = True
            if m_s == 0 and abs(vpre) <= decouple_tol * vel_scale and rb_n >= 6:
                other = -1
                nset = 1
                for b in range(6):
                    c = rb_c[(rb_pos - b) % RB]
                    if c != j:
                        if other < 0:
                            other = c
                            nset = 2
                        elif c != other:
                            nset = 3
                if nset == 1 and fall > 0.0:
                    m_s = 1
                elif nset == 2:
                    m_s = 2
                    sidx[1] = other
                    lT = _remaining_log2_time(rb_c, rb_ldt, rb_lu, rb_pos, rb_n)
                    if lT > -1e300:
                        T = math.exp2(lT - (kq - kv))
                    elif fall > 0.0:
                        T = 2.0 * max(abs(vpre), vplus) / fall
                    else:
                        m_s = 0
                if m_s > 0 and not T <= rem:
                    m_s = 0
            if m_s == 0:
                continue
            # complete: the state at the accumulation is the Θ-projection of the free
            # state after T onto the constraints of the chattering contacts
            for i in range(3):
                q_pre[i] = q[i]
                p_pre[i] = p[i]
                qs[i] = abs(q[i]) + abs(p[i]) * T
                ps[i] = abs(p[i])
                qn[i] = q[i] + p[i] * T
                pn[i] = p[i]
            qs[2] += 0.5 * gt * T * T
            ps[2] += gt * T
            qn[2] -= 0.5 * gt * T * T
            pn[2] -= gt * T
            lam_acc = -_dot(F, j, pn) / w[j, j] if m_s == 1 else math.nan
            for i in range(3):
                q[i] = qn[i]
                p[i] = pn[i]
            _project(q, F, tinv, sidx, m_s)
            _project(p, F, tinv, sidx, m_s)
            t_hi, t_lo = _add_time(t_hi, t_lo, math.ldexp(T, kq - kv))
            for b in range(m_s):
                closed[sidx[b]] = True
            Ea = _energy(q, p, thd, mass, gt)
            _write_row(out_i, out_f, out_s, n_ev, record_states, ACCUMULATION, sidx[0],
                       sidx[1] if m_s == 2 else -1, kv, kq, held, T, t_hi, t_lo, lam_acc,
                       abs(vpre), 0.0, E, Ea, q_pre, p_pre, q, p, acc)  # fmt: skip
            n_ev += 1
            rb_n = 0
            if not exact:
                for c in range(nc):
                    if closed[c]:
                        continue
                    if _dot(F, c, q) <= _tol(F, c, qs, 0.0):
                        status = SIMULTANEOUS
                        reason = 5 if m_s == 1 else 6
                        info[3] = j
                        info[4] = c
            if status >= 0:
                break
            continue

        # ---------------------------------------------------------- held set
        ncl = _closed_indices(closed, nc, cidx)
        if ncl >= rank_f:
            status = SINGULARITY
            reason = 7
            break
        for _it in range(4):
            nh = _held_solve(F, tinv, gt, cidx, ncl, acc, held)
            if nh < 0:
                status = FAILED
                reason = 8
                break
            for a in range(ncl):
                c = cidx[a]
                if c != held[0] and c != held[1] and c != held[2] and _dot(F, c, acc) > 0.0:
                    closed[c] = False  # closed, not held, accelerating away: lift-off
            added = False
            for c in range(nc):
                if closed[c]:
                    continue
                if _dot(F, c, q) <= _tol(F, c, qs, 0.0) and abs(_dot(F, c, p)) <= _tol(
                    F, c, ps, vfl
                ):
                    if _dot(F, c, acc) < 0.0:
                        closed[c] = True  # touching at rest and pushed down
                        added = True
            if not added:
                break
            ncl = _closed_indices(closed, nc, cidx)
            if ncl >= rank_f:
                status = SINGULARITY
                reason = 7
                break
        if status >= 0:
            break
        row = n_ev - 1
        out_i[row, I_HELD1] = held[0]
        out_i[row, I_HELD2] = held[1]
        if record_states:
            for i in range(3):
                out_s[row, 12 + i] = acc[i]
        nh = 0
        for b in range(3):
            if held[b] >= 0:
                hidx[nh] = held[b]
                nh += 1

        # ---------------------------------------------------------- next event
        tmin = math.inf
        jmin = -1
        for c in range(nc):
            if closed[c]:
                continue
            gap = _dot(F, c, q)
            v = _dot(F, c, p)
            ac = _dot(F, c, acc)
            if gap <= _tol(F, c, qs, 0.0):
                if v <= _tol(F, c, ps, vfl):
                    continue  # touching, not approaching, not pushed down: leaves
                tc = first_hit(0.0, v, ac)
            else:
                tc = first_hit(gap, v, ac)
            if tc < tmin:
                tmin = tc
                jmin = c
        rem = math.inf
        if math.isfinite(t_end):
            rem = math.ldexp((t_end - t_hi) - t_lo, kv - kq)
        if tmin >= rem or jmin < 0:
            if not math.isfinite(rem):
                status = FAILED
                reason = 10
                break
            tmin = max(rem, 0.0)
            jmin = -1
        for i in range(3):
            qs[i] = abs(q[i]) + abs(p[i]) * tmin + 0.5 * abs(acc[i]) * tmin * tmin
            ps[i] = abs(p[i]) + abs(acc[i]) * tmin
            q[i] = q[i] + p[i] * tmin + 0.5 * acc[i] * tmin * tmin
            p[i] = p[i] + acc[i] * tmin
        if nh > 0:
            _project(q, F, tinv, hidx, nh)
            _project(p, F, tinv, hidx, nh)
        if jmin < 0:
            t_hi, t_lo = t_end, 0.0
            E = _energy(q, p, thd, mass, gt)
            _write_row(out_i, out_f, out_s, n_ev, record_states, END, -1, -1, kv, kq, held,
                       tmin, t_hi, t_lo, 0.0, 0.0, 0.0, E, E, q, p, q, p, acc)  # fmt: skip
            n_ev += 1
            status = T_END
            break
        # the contact reached: its gap exactly zero (with the held ones)
        if nh < 3:
            hidx[nh] = jmin
            _project(q, F, tinv, hidx, nh + 1)
        t_hi, t_lo = _add_time(t_hi, t_lo, math.ldexp(tmin, kq - kv))
        pending_dtn = tmin

    if status != T_END and n_ev < cap:
        E = _energy(q, p, thd, mass, gt)
        _write_row(out_i, out_f, out_s, n_ev, record_states, END, -1, -1, kv, kq, held,
                   pending_dtn, t_hi, t_lo, 0.0, 0.0, 0.0, E, E, q, p, q, p, acc)  # fmt: skip
        n_ev += 1
    info[0] = status
    info[1] = n_ev
    info[2] = n_imp
    info[5] = reason
    return n_ev


@njit(cache=True)
def log2_time_to_go(log2_dt, log2_rest):
    """log2(t_f − t_i) for every event i: log2 of the rest after the last event combined
    with the intervals that follow each event, summed from the end in log space
    (log2_dt[i] is the interval before event i; −inf for none)."""
    n = log2_dt.shape[0]
    out = np.empty(n)
    acc = log2_rest
    for i in range(n - 1, -1, -1):
        out[i] = acc
        x = log2_dt[i]
        if x > acc:
            acc = x + math.log2(1.0 + math.exp2(acc - x))
        elif x > -math.inf:
            acc = acc + math.log2(1.0 + math.exp2(x - acc))
    return out


@njit(cache=True)
def log2_segment_sums(log2_dt, idx):
    """log2 of the time from event idx[k] to event idx[k+1] (the intervals
    log2_dt[idx[k]+1 .. idx[k+1]] summed), for consecutive entries of idx."""
    n = idx.shape[0] - 1
    out = np.empty(max(n, 0))
    for k in range(n):
        acc = -math.inf
        for i in range(idx[k] + 1, idx[k + 1] + 1):
            x = log2_dt[i]
            if x == -math.inf:
                continue
            if x > acc:
                acc = x + math.log2(1.0 + math.exp2(acc - x))
            else:
                acc = acc + math.log2(1.0 + math.exp2(x - acc))
        out[k] = acc
    return out
