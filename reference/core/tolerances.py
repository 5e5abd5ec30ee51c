"""Named tolerances and factors of the exact reference, each with its reason.

Plain module constants: the compiled functions read them as compile-time constants.
"""

EPS = 2.220446049250313e-16  # unit roundoff of a double
# Guards divisions by quantities that may be exactly zero (a body at rest, a contact at
# rest): x / max(y, TINY).  It is far below any physical value the inputs allow.
TINY = 1e-300

# Roundoff level of a gap, in ulps of the terms that form it: the gap z + r_z (or
# (x − b)·e3) is a sum of a few products, each good to an ulp or two.
GAP_NOISE_ULPS = 8.0
# Roundoff level of a normal velocity, in ulps of the velocity scale V = |v| + a|ω|: it
# is a sum of up to six products of velocities and levers.
RATE_NOISE_ULPS = 64.0

# A touch slower than GRAZE_FACTOR × √(2 g″ noise) cannot be told from a double root
# (a graze): a convex gap reaches that speed inside its own roundoff band.
GRAZE_FACTOR = 4.0
# Two contacts whose zeros are within this many times the sum of their time resolutions
# (noise / |rate|) are reached together: the model cannot order them (simultaneous).
SIMULTANEOUS_FACTOR = 4.0

# Derivative bounds K, B are enlarged by this factor (and by BOUND_ULPS·ε of their
# terms) so that roundoff in forming them never makes them too small.
BOUND_MARGIN = 1.0001
BOUND_ULPS = 16.0
# A safe step needs the first root of its lower bound only to this relative accuracy:
# near a real contact the quadratic bound already gives the Newton-like step.
ROOT_REL_TOL = 1e-3
# The search always advances by at least this fraction of the elapsed time, so a contact
# resting with g′ ≈ g″ ≈ 0 cannot stall it (it leaves at roundoff pace).
MIN_STEP_REL = 1e-15
# Newton polishing of an impact time: at most this many steps, stopping once the
# correction is below POLISH_REL_TOL of the time.
POLISH_ITERATIONS = 3
POLISH_REL_TOL = 1e-16
# Newton steps (bisection when they leave the bracket) for a bracketed zero: Newton
# converges in a handful from the bracket's safe end; the cap only guards the loop.
BRACKET_ITERATIONS = 60
# Free-flight search iterations before the run is declared stuck.
MAX_SEARCH_ITERATIONS = 100_000
# Progress (reference.core.loop._stalled): a window of STALL_WINDOW loop steps without
# an impact must advance the clock by STALL_WINDOW × contact_rtol × T on average (T the
# motion's time scale), else the run ends `stalled`.  Long enough that no legitimate
# stretch without impacts is judged: none of the check scenes has one of 1,000 steps
# under any law but a creeping run (docs/architecture.md, statuses), and short enough
# to end a creeping run within a few seconds (≤ 2 windows, ~10 µs a step).
STALL_WINDOW = 100_000

# Large polygons: for n > SMALL_N a search step near the ground examines only the
# vertices near the lowest direction (far from it the circle through the vertices bounds
# them all for any n; reference.core.search).
# Measured (callgrind instructions per 20,000 elastic impacts, window against every
# vertex, both with the circle far from the ground): n = 17 +6 % (fast spin) / +7 %
# (tumbling), 18 +5 / +3 %, 19 +3 / +7 %, 20 −2 / −1 %, 24 −12 / −13 %.  Every vertex
# pays below the crossover, the window above it.
SMALL_N = 19
# The circle step of large polygons (reference.core.rim.circle_root) solves its
# bound to this relative tolerance (from below: any value is safe; a looser one
# shortens the step by as much and saves iterations of the solve).
CIRCLE_STEP_REL_TOL = 1e-2
# The circle's lowest point is followed on its closed form (reference.core.rim.
# rim_descent) for at most this many steps per search iteration: each shrinks its gap by
# a factor near the ground (a lower bound's second-order loss), and costs a cosine, a
# sine and a root rather than a state and the vertices near the ground.
RIM_DESCENT_STEPS = 32
# Newton steps locating where the circle's lowest point is two sags above the ground,
# to within a sag (reference.core.rim.rim_target): at most RIM_NEWTON_STEPS (the point
# only ends the descent: any time whose backward bound holds is safe).
RIM_NEWTON_STEPS = 8
# A contact phase examines the vertices whose gap may be within its touching tolerance
# and WINDOW_MAX more on each side (reference.core.candidates).  A flight search step
# starts from those that can be at the ground now and two more on each side, and grows
# the window as its step needs (search.near_vertices_step): starting it with WINDOW_MAX
# more as well cost 6.7 % more instructions per impact on a spinning 100-gon (γ = 1)
# and 5.7 % on a tumbling 1000-gon (callgrind, eight runs of 2,500 impacts each).
WINDOW_MAX = 3
# The lowest direction of a large polygon is found to within ANGLE_ERROR radians
# (reference.core.window.direction_angle: a series whose remainder is below 2e-10) and
# its vertex window widened by as much: one vertex of n = 1e6 is 6.3e-6 rad.
ANGLE_ERROR = 1e-9
# A search step may examine SEARCH_WINDOW_GROW vertices beyond those, else its step is
# shortened by SEARCH_SHRINK until that suffices.
SEARCH_WINDOW_GROW = 12
SEARCH_SHRINK = 0.25
# A contact step adds at most WINDOW_GROW vertices at a time to those it examines, else
# shortens its chunk (×¼); after WINDOW_ROUNDS rounds it examines every vertex
# (reference.core.candidates).
WINDOW_GROW = 16
WINDOW_ROUNDS = 64

# Chatter: a bounce lower than CHATTER_BOUNCE_FLOOR² roundoff bands of its gap (speed
# below CHATTER_BOUNCE_FLOOR √(2 |a_n| noise)) cannot be resolved one impact at a time;
# completion takes over (reference.core.chatter).
CHATTER_BOUNCE_FLOOR = 100.0

# Contact phases: the gap resolution is CONTACT_GAP_RES × rtol × the length scale (the
# integrator resolves positions to ~rtol of the phase's size).
CONTACT_GAP_RES = 16.0
# Chunk horizon (reference.core.horizon): K = HORIZON_ACC_FACTOR max|g″| + g over the free
# contacts; at most LOCAL_TIME_FRACTION of the local time scale √(L_reach/K) and of the
# time ROTATION_TIME_FACTOR·a/V the rim takes to move its own radius, or the integrator's
# own next step when that is longer (candidates.certified_horizon); a force falling at its
# current rate may reach zero only after FORCE_TREND_FACTOR chunks of its current value.
HORIZON_ACC_FACTOR = 2.0
LOCAL_TIME_FRACTION = 0.25
ROTATION_TIME_FACTOR = 2.0
FORCE_TREND_FACTOR = 1.5
# A chunk at most HEUN_STEP_RATIO of the integrator's step is one Heun–Euler step
# (phases._short_chunk): at rtol = 1e-12 DOP853 steps ~rtol^(1/9) ≈ 0.05 of the local
# time scale T, and the pair's order-1 error estimate (s/T)² passes rtol for s ≲ 1e-6 T.
HEUN_STEP_RATIO = 1e-5
# Two Gauss–Newton passes bring held gaps back to roundoff after a chunk.
PROJECTION_PASSES = 2
# Lift-off and crossing times inside a chunk: located to LOCATE_XTOL × the chunk length
# (and 4 ε relative), at most LOCATE_ITERATIONS function evaluations.
LOCATE_XTOL = 1e-15
LOCATE_ITERATIONS = 200

# End of the motion: once impacts have happened, a tilt α below TILT_FLOOR (rad) is the
# singularity for double precision: α² (heights' curvature terms, energies ∝ α²) would
# underflow below 1e-300 and time scales ∝ √α lose their digits, so the model cannot
# decide anything further (a sweep run reached α = 4e-296 and divided by zero).  An
# exactly flat body (α = 0, e.g. landing flat) is left to the event search.
TILT_FLOOR = 1e-150

# t_singularity extrapolated from the last impacts (loop.extrapolate_singularity): blocks
# of up to MAX_PERIOD impacts, accepted when the last two blocks' ratios agree to
# PERIOD_RATIO_TOL (relative).  A triangle's vertices take turns: its single intervals
# alternate (ratios 0.81, 1.09, ...) while pairs shrink by 0.86 each.
MAX_PERIOD = 6
PERIOD_RATIO_TOL = 0.05
