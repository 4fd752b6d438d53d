"""Why the default is the default, from the speed-against-error data: the section of
speed_error.md that states the rule the defaults are chosen by, applies it to the sweep, and
says whether the engine's default is the setting the rule picks. Used by plot_speed_error.py.

The rule: among the fixed settings run on every swept case at the scenes' step (the step is the
scene's, shared/SCENES.md: 1/60 s; a different dt is shown for what it buys, not a candidate
default), keep those that meet every case's accuracy bound (BOUNDS; each says why it is that
number), then take the cheapest by the geometric mean over the cases of cost / the default's
cost. Costs within the cost noise of the cheapest are a tie (a shared machine cannot tell them
apart), broken by the geometric mean of error / the default's error (errors below the floor
count as the floor, errors within the noise as equal, and the event cases' errors not at all);
a default within the error noise of the most accurate tied setting stays the default. A ball
out of the pit fails any case."""
import math

# Errors within this fraction (or below ERROR_FLOOR) are the same error.
ERROR_NOISE = 0.02
ERROR_FLOOR = 1e-6
# Cases whose error is chaotic get a wider noise. The character's worst overlap after a step is
# one pinch of a ball between a limb and the pile: at the default setting it measured 0.24, 0.99
# and 0.71 r with 4,800, 5,000 and 5,200 balls (top ball speed 3.6, 22.9 and 3.6 m/s), so errors
# within 4x of each other are the same error. The crowd's is the worst of 5 random spawns: at
# the default, 10 spawns made 0.03 to 0.6 m/s, so under its bound errors within 10x are the same.
# The pour's is the deepest of its pile's overlaps, one pair that chaos places: solver variants
# that changed a few contacts gave 0.000084 to 0.0013 r at 10k (and 0.00067 to 0.0019 r at
# 100k), so errors within 10x are the same there too. A case named "pour-10k" takes "pour"'s.
# The gas's energy drift is set by whether one of 10,000 steps' wall hits goes wrong: at the
# default, gases spawned from seeds 1 to 5 drifted 0.0022, 0.00004, 0.00004, 0.00004 and 0.00004
# (the sweep's own spawn 0.0023), and at a 2 m/s push-out cap seeds 1 to 3 drifted 0.0012,
# 0.0020 and 0.00004, so under its bound errors within 100x are the same.
CASE_ERROR_NOISE = {"character": 0.75, "crowd": 0.9, "pour": 0.9, "gas": 0.99}
# Between settings that meet their bounds the rule does not compare these cases' errors at all:
# each is one event (a pinch; the worst of 5 spawns), and the 3 ball counts and 10 spawns above
# are too few to say how wide their noise is.
EVENT_CASES = ("character", "crowd")


def same_error(a, b, case=None):
    a, b = max(a, ERROR_FLOOR), max(b, ERROR_FLOOR)
    noise = bound_for(case, CASE_ERROR_NOISE) if case else None
    return abs(a - b) <= (ERROR_NOISE if noise is None else noise) * max(a, b)


def failure(point, case, bounds=None):
    """Why this point fails its case (over the case's bound, or a ball out of the pit), or None."""
    b = bound_for(case, BOUNDS if bounds is None else bounds)
    if b and bounded_value(point, b) > b[0]:
        return case
    if point.get("escaped", 0) > 0:
        return f"{case} (a ball out of the pit)"
    return None


def meets_bound(point, case, bounds=None):
    return failure(point, case, bounds) is None

# Accuracy bound per case and the reason for it: (limit, why) on the case's error axis, or
# (limit, why, field) on another figure of its runs. Cases not listed (or a case whose name
# starts with a listed prefix, e.g. pour-10k for "pour") have no bound.
BOUNDS = {
    "bounce": (0.01, "the apex of each of 3 bounces within 1% of H e^2k"),
    "cradle": (0.01, "at most 1% of the momentum anywhere but the last ball"),
    "stack": (0.25, "a 50-ball column sinks, drifts or overlaps by less than a quarter radius in 20 s"),
    "gas": (0.01, "kinetic energy kept within 1% over 10,000 elastic steps"),
    "pour": (0.01, "deepest overlap at the end under 1% r, SCENES.md's depth for a ball 'inside'"),
    "crowd": (1.0, "the solver makes no ball more than 1 m/s faster than falling would while a crowd "
                   "spawned inside itself separates: issue 2's hard case at a 1 m/s push-out cap, "
                   "held in m/s for every setting (a larger cap must not buy a looser bound)"),
    "character": (0.01, "no ball left inside a collider (deeper than 1% r, SCENES.md) after any step; its "
                        "error axis, the worst overlap of any kind after a step, comes from single jams "
                        "(a ball pinched between a limb and the pile) and has no bound here",
                  "max_collider_penetration_r"),
}


def bound_for(case, bounds=BOUNDS):
    for name, value in bounds.items():
        if case == name or case.startswith(name + "-"):
            return value
    return None


def bounded_value(point, bound):
    """The figure a bound applies to: the error, or the field the bound names."""
    return point.get(bound[2], float("inf")) if len(bound) > 2 else point["error"]


def geomean(xs):
    xs = list(xs)
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else float("nan")


def choose(by_case, swept_cases, cost_noise, error_floor, bounds=BOUNDS):
    """Returns (candidates, chosen): candidates are dicts with the setting's label, whether it
    meets every bound, the cases it fails, and its geometric-mean cost and error relative to the
    default; chosen is the candidate the rule picks (None if no setting meets every bound)."""
    defaults = {c: next((p for p in by_case[c] if p["point"] == "default"), None) for c in swept_cases}
    cases = [c for c in swept_cases if defaults[c]]
    labels = None
    for c in cases:
        step = defaults[c]["dt"]
        here = {p["point"] for p in by_case[c] if "tolerance_r" not in p and p["dt"] == step}
        labels = here if labels is None else labels & here
    candidates = []
    for label in sorted(labels or []):
        runs = {c: next(p for p in by_case[c] if p["point"] == label) for c in cases}
        fails = [f for f in (failure(p, c, bounds) for c, p in runs.items()) if f]
        d_cost = {c: defaults[c]["cost_ms_per_sim_s"] for c in cases}
        candidates.append({
            "point": label,
            "meets_all": not fails,
            "fails": fails,
            "cost_vs_default": geomean(runs[c]["cost_ms_per_sim_s"] / d_cost[c] for c in cases),
            "error_vs_default": geomean(error_ratio(runs[c], defaults[c], c, error_floor) for c in cases),
        })
    ok = [c for c in candidates if c["meets_all"]]
    if not ok:
        return candidates, None
    cheapest = min(c["cost_vs_default"] for c in ok)
    tied = [c for c in ok if c["cost_vs_default"] <= cheapest * (1 + cost_noise)]
    best = min(tied, key=lambda c: (c["error_vs_default"], c["cost_vs_default"]))
    # Moving the default takes a reason beyond the noise: tied on cost and within the error noise
    # of the most accurate, it stays.
    default = next((c for c in tied if c["point"] == "default"), None)
    if default and default["error_vs_default"] <= best["error_vs_default"] * (1 + ERROR_NOISE):
        return candidates, default
    return candidates, best


def error_ratio(run, default, case, error_floor):
    """A setting's error / the default's in one case; 1 when they are within the case's noise or
    the case is an event case."""
    if case in EVENT_CASES or same_error(run["error"], default["error"], case):
        return 1.0
    return max(run["error"], error_floor) / max(default["error"], error_floor)


def section(by_case, swept_cases, cost_noise, error_floor, md_table, fmt, bounds=BOUNDS):
    """The markdown section: the rule, the bounds, the settings that meet them, the verdict."""
    candidates, chosen = choose(by_case, swept_cases, cost_noise, error_floor, bounds)
    out = ["## Why the default is the default\n",
           "The rule the defaults are chosen by, applied to the runs above: among the fixed "
           "settings run on every swept case at the scenes' step (1/60 s, shared/SCENES.md: the "
           "step belongs to the scene, so the dt points show what a finer or coarser step buys "
           "but are not candidate defaults), keep those that meet every case's accuracy bound, "
           "then take the cheapest by the geometric mean over the cases of cost / the default's "
           f"cost; settings within {cost_noise:.0%} of the cheapest are a tie (the machine's "
           "noise), broken by the geometric mean of error / the default's error, where errors "
           f"within a case's noise count as equal ({ERROR_NOISE:.0%}; " +
           ", ".join(f"{c} {1 / (1 - n):.0f}x" for c, n in CASE_ERROR_NOISE.items() if c not in EVENT_CASES) +
           ") and the errors of " + " and ".join(EVENT_CASES) +
           " are not compared (each is one event: a pinch of a ball under a limb, the worst of 5 "
           "random spawns; only their bounds count); a default within the error noise of the most "
           "accurate tied setting stays the default (moving it takes a reason beyond the noise). A "
           "ball out of the pit fails any case. "
           "Tolerance points are not candidates: they are a mode (`--tolerance`), not a setting.\n"]
    rows = []
    for c in swept_cases:
        b = bound_for(c, bounds)
        on = (b[2] if len(b) > 2 else "error") if b else ""
        rows.append([c, fmt(b[0]) if b else "none", on, b[1] if b else ""])
    out.append(md_table(["case", "bound", "on", "why"], rows))
    if not candidates:
        out.append("\nNo fixed setting ran on every swept case, so the rule cannot be applied "
                   "(run the sweep with the default and its variations on every case).\n")
        return "\n".join(out)
    rows = []
    for c in sorted(candidates, key=lambda c: (not c["meets_all"], c["cost_vs_default"])):
        label = f"**{c['point']}**" if chosen and c["point"] == chosen["point"] else c["point"]
        rows.append([label, "yes" if c["meets_all"] else "no: " + ", ".join(c["fails"]),
                     fmt(c["cost_vs_default"]), fmt(c["error_vs_default"])])
    out.append("\n" + md_table(["setting", "meets every bound", "cost / default (geo. mean)",
                                "error / default (geo. mean)"], rows))
    default = next((c for c in candidates if c["point"] == "default"), None)
    if chosen is None:
        out.append("\nNo fixed setting meets every bound: the default is a compromise the bounds do "
                   "not decide" + (f" (it fails: {', '.join(default['fails'])})" if default else "") + ".\n")
    elif chosen["point"] == "default":
        out.append("\n**The rule picks the engine's default**: it meets every bound, and no setting "
                   "that does is cheaper beyond the noise" +
                   (" or, at a tied cost, more accurate beyond the noise" if len(candidates) > 1 else "") + ".\n")
    else:
        verdict = ("it meets every bound too, but " if default and default["meets_all"] else
                   f"it fails the bound of {', '.join(default['fails'])}, and " if default else "")
        out.append(f"\n**The rule picks {chosen['point']}, not the engine's default**: {verdict}"
                   f"{chosen['point']} costs {fmt(chosen['cost_vs_default'])}x the default for "
                   f"{fmt(chosen['error_vs_default'])}x its error (geometric means). The default "
                   "should move there unless another case says otherwise.\n")
    return "\n".join(out)
