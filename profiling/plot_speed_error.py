#!/usr/bin/python3
"""Speed-against-error report: reads the JSON lines of profiling/speed_error (one per case and
solver setting) and writes a CSV, a Pareto plot (cost against error, one panel and one front
per case, plus all fronts on one normalised panel) and a markdown table that says, per case,
which settings are on the Pareto front, whether the default is, where the tolerance-mode points
(`--tolerance P`) land against the fixed settings, and why the default is the default
(speed_error_choice.py). Run by scripts/profile_speed_error.sh."""
import argparse
import csv
import math
import os

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from report_common import load_jsonl, machine_line, md_table  # noqa: E402
from speed_error_choice import ERROR_FLOOR, ERROR_NOISE, EVENT_CASES, meets_bound, same_error  # noqa: E402
from speed_error_choice import section as choice_section  # noqa: E402

# Cost is wall time, measured on a shared machine: two costs within this fraction are the same.
COST_NOISE = 0.10

CASE_ORDER = ["bounce", "cradle", "stack", "gas", "crowd", "character"]
# Settings shown in the tables when the sweep has them (the solver's knobs change over time;
# the CSV keeps every field whatever it is).
SETTING_COLUMNS = [("substeps", "substeps"), ("solve_sweeps", "sweeps"), ("push_out_rate", "push rate"), ("push_out_speed", "push-out (m/s)"),
                   ("contact_hertz", "hertz"), ("damping_ratio", "damping"),
                   ("restitution_threshold", "threshold (m/s)"), ("dt", "dt (s)")]
# Per-case figures shown in the markdown (besides cost and error).
DETAILS = {
    "bounce": [("apex_m", "apex heights (m)")],
    "cradle": [("delivered", "p_last / p0"), ("max_penetration_r", "max pen / r")],
    "stack": [("drift_r", "drift / r"), ("max_penetration_r", "overlap / r"),
              ("max_wall_penetration_r", "floor overlap / r")],
    "gas": [("energy_drift", "KE drift"), ("max_abs_energy_drift", "worst |KE drift|"), ("escaped", "escaped")],
    "crowd": [("max_ball_speed_mps", "top ball speed (m/s)"), ("escaped", "escaped"),
              ("max_penetration_r", "overlap at 5 s / r")],
    "character": [("max_collider_penetration_r", "deepest in a collider / r"),
                  ("balls_inside_colliders", "balls inside (worst step)"), ("max_ball_speed_mps", "top ball speed (m/s)"),
                  ("ball_speed_bound_mps", "strike bound (m/s)"), ("max_penetration_r", "ball-ball pen / r"),
                  ("escaped", "escaped")],
    "pour": [("max_penetration_r", "max pen / r"), ("mean_penetration_r", "mean pen / r"),
             ("kinetic_energy_j", "KE end (J)"), ("settle_s", "settle (s)"), ("escaped", "escaped")],
}


def details_for(case):
    return (DETAILS["pour"] if case.startswith("pour") else DETAILS.get(case, [])) + \
        [("max_step_penetration_r", "worst overlap after a step / r"),
         ("mean_step_penetration_r", "mean overlap after a step / r")]


def is_tolerance(p):
    """A tolerance-mode point: the substep controller chose its substeps every step."""
    return "tolerance_r" in p


def substeps_cell(p):
    if is_tolerance(p) and "substeps_mean" in p:
        return f"{p['substeps_mean']:.1f} ({p['substeps_min']}..{p['substeps_max']})"
    return fmt(p.get("substeps"))


def dominates(q, p):
    """q is at least as good as p in cost and error (within noise) and clearly better in one.
    Two settings that end in the same state hash computed the same thing: neither dominates."""
    if q["state_hash"] == p["state_hash"]:
        return False
    cheaper = q["cost_ms_per_sim_s"] < p["cost_ms_per_sim_s"] * (1 - COST_NOISE)
    not_dearer = q["cost_ms_per_sim_s"] <= p["cost_ms_per_sim_s"] * (1 + COST_NOISE)
    better = q["error"] < p["error"] and not same_error(q["error"], p["error"], p["case"])
    not_worse = q["error"] <= p["error"] or same_error(q["error"], p["error"], p["case"])
    return (cheaper and not_worse) or (not_dearer and better)


def jointly_dominates(runs, defaults):
    """runs and defaults map case -> point. A setting beats the default jointly when in every case
    both ran it is no dearer (within noise), no less accurate and meets every bound the default
    meets, and it dominates the default in one. An event case's error (EVENT_CASES) is not
    compared: there only cost and the bound count."""
    shared = [c for c in runs if c in defaults]

    def no_worse(q, d):
        if q["state_hash"] == d["state_hash"]:
            return True
        if meets_bound(d, d["case"]) and not meets_bound(q, d["case"]):
            return False
        return (q["cost_ms_per_sim_s"] <= d["cost_ms_per_sim_s"] * (1 + COST_NOISE) and
                (d["case"] in EVENT_CASES or q["error"] <= d["error"] or same_error(q["error"], d["error"], d["case"])))

    def beats(q, d):
        if d["case"] in EVENT_CASES:
            return q["cost_ms_per_sim_s"] < d["cost_ms_per_sim_s"] * (1 - COST_NOISE)
        return dominates(q, d)

    return bool(shared) and all(no_worse(runs[c], defaults[c]) for c in shared) and \
        any(beats(runs[c], defaults[c]) for c in shared)


def neighbours(default, ps):
    """Why the default sits where it does: its nearest front neighbours on either side."""
    def equivalent(p):  # same error and a cost within noise: the default again, in effect
        return (same_error(p["error"], default["error"], default["case"]) and
                abs(p["cost_ms_per_sim_s"] / default["cost_ms_per_sim_s"] - 1) <= COST_NOISE)

    front = [p for p in ps if p["pareto"] and not is_tolerance(p) and p["state_hash"] != default["state_hash"]
             and not equivalent(p)]
    cheaper = [p for p in front if p["cost_ms_per_sim_s"] < default["cost_ms_per_sim_s"]]
    dearer = [p for p in front if p["cost_ms_per_sim_s"] >= default["cost_ms_per_sim_s"]]
    lines = []
    d_err = max(default["error"], ERROR_FLOOR)
    if cheaper:
        q = max(cheaper, key=lambda p: p["cost_ms_per_sim_s"])
        lines.append(f"the next cheaper setting on the front, {q['point']}, costs "
                     f"{1 - q['cost_ms_per_sim_s'] / default['cost_ms_per_sim_s']:.0%} less and its error is "
                     f"{max(q['error'], ERROR_FLOOR) / d_err:.3g}x the default's")
    if dearer:
        q = min(dearer, key=lambda p: p["cost_ms_per_sim_s"])
        lines.append(f"the next dearer one, {q['point']}, costs "
                     f"{q['cost_ms_per_sim_s'] / default['cost_ms_per_sim_s'] - 1:.0%} more for an error "
                     f"{max(q['error'], ERROR_FLOOR) / d_err:.3g}x the default's")
    return ("Around the default: " + "; ".join(lines) + ".\n") if lines else ""


def mark_fronts(ps):
    """Fixed settings form the front among themselves (is the default on it?); a tolerance point
    is on the front when nothing at all dominates it."""
    fixed = [q for q in ps if not is_tolerance(q)]
    default = next((q for q in ps if q["point"] == "default"), None)
    for p in ps:
        rivals = ps if is_tolerance(p) else fixed
        p["pareto"] = not any(dominates(q, p) for q in rivals if q is not p)
        p["cost_vs_default"] = p["cost_ms_per_sim_s"] / default["cost_ms_per_sim_s"] if default else None
        p["dominates_default"] = bool(default) and p is not default and dominates(p, default)


def tolerance_lines(ps, default):
    """Where each tolerance point lands: what it achieved, what it cost, and against what."""
    lines = []
    fixed = [q for q in ps if not is_tolerance(q)]
    for p in sorted((p for p in ps if is_tolerance(p)), key=lambda p: -p["tolerance_r"]):
        P = p["tolerance_r"]
        held = p.get("max_step_penetration_r")
        text = (f"- `--tolerance {P:g}`: worst overlap after a step {fmt(held)} r "
                f"({'within' if held is not None and held <= P else 'over'} P"
                + (f"; {p['steps_over_tolerance']} of {p['steps']} steps over it" if "steps_over_tolerance" in p else "")
                + f"), substeps {substeps_cell(p)}, error {fmt(p['error'])}")
        if default:
            text += f", cost {fmt(p['cost_ms_per_sim_s'] / default['cost_ms_per_sim_s'])}x the default's"
        beaten = [q["point"] for q in fixed if dominates(q, p)]
        beats = [q["point"] for q in fixed if dominates(p, q)]
        text += ("; on the front" if p["pareto"] else "; dominated by " + ", ".join(beaten))
        if beats:
            text += "; dominates " + ", ".join(beats)
        # The cheapest fixed setting whose own worst overlap after a step also stayed within P.
        also = [q for q in fixed if q.get("max_step_penetration_r") is not None and q["max_step_penetration_r"] <= P]
        if also:
            q = min(also, key=lambda q: q["cost_ms_per_sim_s"])
            text += (f"; the cheapest fixed setting that also kept every step within P is {q['point']} "
                     f"at {fmt(q['cost_ms_per_sim_s'] / p['cost_ms_per_sim_s'])}x this cost")
        else:
            text += "; no fixed setting kept every step within P"
        lines.append(text + ".")
    return ("Tolerance mode:\n\n" + "\n".join(lines) + "\n") if lines else ""


def fmt(v):
    if v is None:
        return ""
    if isinstance(v, list):
        return ", ".join(fmt(x) for x in v)
    if isinstance(v, float):
        if v == 0:
            return "0"
        if abs(v) >= 1000 or abs(v) < 1e-3:
            return f"{v:.3g}"
        return f"{v:.4g}"
    return str(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("jsonl")
    ap.add_argument("--csv", required=True)
    ap.add_argument("--png", required=True)
    ap.add_argument("--md", required=True)
    a = ap.parse_args()
    points = load_jsonl(a.jsonl)
    cases = []
    for p in points:
        if p["case"] not in cases:
            cases.append(p["case"])
    cases.sort(key=lambda c: (CASE_ORDER.index(c) if c in CASE_ORDER else len(CASE_ORDER), c))

    by_case = {c: [p for p in points if p["case"] == c] for c in cases}
    for ps in by_case.values():
        mark_fronts(ps)
    # Plot-only views: each pour again with the worst overlap after a step as its error, the
    # quantity --tolerance bounds, so the tolerance points land against what they promise.
    step_views = {}
    for c in cases:
        if c.startswith("pour") and all("max_step_penetration_r" in p for p in by_case[c]):
            view = [dict(p, error=p["max_step_penetration_r"],
                         error_metric="worst overlap after a step / r (what --tolerance bounds)") for p in by_case[c]]
            mark_fronts(view)
            step_views[c + ", per step"] = view
    plot_cases = cases + list(step_views)
    plot_by_case = {**by_case, **step_views}

    # CSV: every field of every line, in first-seen order.
    fields = []
    for p in points:
        for k in p:
            if k not in fields:
                fields.append(k)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for p in points:
            w.writerow({k: (";".join(map(str, v)) if isinstance(v, list) else v) for k, v in p.items()})

    # Plot: one panel per case, then all fronts normalised by the default.
    panels = len(plot_cases) + 1
    cols = 3
    rows = math.ceil(panels / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.2 * rows))
    axes = axes.flatten()
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    overlay = axes[len(plot_cases)]
    for i, c in enumerate(plot_cases):
        ax = axes[i]
        ps = plot_by_case[c]
        color = colors[i % len(colors)]
        fixed = [p for p in ps if not is_tolerance(p)]
        ax.scatter([p["cost_ms_per_sim_s"] for p in fixed], [max(p["error"], ERROR_FLOOR) for p in fixed],
                   s=14, color="0.6", zorder=2)
        # Settings that computed the same state (same hash) are one point of the front: drawn
        # once, at the cheapest run, labelled by the first of them (the default if it is one).
        groups = {}
        for p in sorted((p for p in fixed if p["pareto"]), key=lambda p: (p["point"] != "default",
                                                                         p["cost_ms_per_sim_s"])):
            groups.setdefault(p["state_hash"], []).append(p)
        front = []
        for g in groups.values():
            rep = dict(min(g, key=lambda p: p["cost_ms_per_sim_s"]))
            rep["point"] = g[0]["point"] + (f" (+{len(g) - 1} same)" if len(g) > 1 else "")
            front.append(rep)
        front.sort(key=lambda p: p["cost_ms_per_sim_s"])
        ax.plot([p["cost_ms_per_sim_s"] for p in front], [max(p["error"], ERROR_FLOOR) for p in front],
                "o-", color=color, zorder=3, label="Pareto front")
        labelled = []
        for k, p in enumerate(front):
            # Label a front point unless one already labelled sits on top of it (the table in
            # the markdown names every point); alternate offsets for neighbours.
            x, y = math.log10(p["cost_ms_per_sim_s"]), math.log10(max(p["error"], ERROR_FLOOR))
            if any(abs(x - lx) < 0.04 and abs(y - ly) < 0.15 for lx, ly in labelled):
                continue
            labelled.append((x, y))
            ax.annotate(p["point"], (p["cost_ms_per_sim_s"], max(p["error"], ERROR_FLOOR)), fontsize=6,
                        xytext=(4, 4 if k % 2 == 0 else -9), textcoords="offset points")
        # Tolerance mode: where it lands against the fixed settings, labelled by P.
        tol = [p for p in ps if is_tolerance(p)]
        if tol:
            ax.scatter([p["cost_ms_per_sim_s"] for p in tol], [max(p["error"], ERROR_FLOOR) for p in tol],
                       marker="^", s=60, color="black", zorder=5, label="--tolerance P")
            for p in tol:
                ax.annotate(f"P={p['tolerance_r']:g}", (p["cost_ms_per_sim_s"], max(p["error"], ERROR_FLOOR)),
                            fontsize=6, xytext=(4, -10), textcoords="offset points")
                if c in step_views:  # the bound each one was asked to keep
                    ax.axhline(p["tolerance_r"], color="black", ls=":", lw=0.6)
        default = next((p for p in ps if p["point"] == "default"), None)
        if default:
            ax.scatter([default["cost_ms_per_sim_s"]], [max(default["error"], ERROR_FLOOR)], marker="*", s=160,
                       color="red", zorder=4, label="default")
        if default and c in by_case:  # the overlay shows each case once, on its own error
            normalised = [(p["cost_ms_per_sim_s"] / default["cost_ms_per_sim_s"],
                           max(p["error"], ERROR_FLOOR) / max(default["error"], ERROR_FLOOR)) for p in front]
            overlay.plot([x for x, _ in normalised], [y for _, y in normalised], "o-", color=color, label=c)
            if tol:
                overlay.scatter([p["cost_ms_per_sim_s"] / default["cost_ms_per_sim_s"] for p in tol],
                                [max(p["error"], ERROR_FLOOR) / max(default["error"], ERROR_FLOOR) for p in tol],
                                marker="^", s=40, color=color, edgecolors="black", zorder=5)
        ax.set_xscale("log")
        ax.set_yscale("log")
        # Plain numbers on the cost axis: a case spanning less than a decade gets minor labels,
        # which matplotlib's default writes as overlapping powers of ten.
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(plain)
        ax.tick_params(axis="x", which="both", labelsize=6)
        ax.set_title(f"{c}: {ps[0]['error_metric']}", fontsize=8)
        ax.set_xlabel("cost: wall ms per simulated s")
        ax.set_ylabel("error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    overlay.scatter([1], [1], marker="*", s=160, color="red", zorder=4, label="default")
    overlay.set_xscale("log")
    overlay.set_yscale("log")
    overlay.set_title("all Pareto fronts, relative to each case's default (triangles: --tolerance)", fontsize=8)
    overlay.set_xlabel("cost / default cost")
    overlay.set_ylabel("error / default error")
    overlay.grid(True, which="both", alpha=0.3)
    overlay.legend(fontsize=7)
    for ax in axes[panels:]:
        ax.axis("off")
    fig.suptitle("Speed against error. " + machine_line(points), fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=100)

    # Markdown.
    out = ["# Speed against error\n",
           f"Generated by `scripts/profile_speed_error.sh` from `{os.path.basename(a.jsonl)}`; every "
           "number below comes from that file. Each row is one run of one case at one solver "
           "setting; ms/step is the median step; the state hash reproduces it exactly (`build/profiling/speed_error --cases CASE "
           "--points LABEL`). Cost is the median step's wall time per simulated second, on the "
           "threads given per case (errors and hashes do not depend on the thread count; small "
           "cases are dominated by per-step overhead, so compare costs within a case). "
           f"A point is on the Pareto front when no other point of its case is at most {COST_NOISE:.0%} "
           f"dearer and clearly more accurate (by more than {ERROR_NOISE:.0%}; for the character, whose "
           "worst step is one chaotic pinch, by more than 4x: at the default it measured 0.24, 0.99 and "
           "0.71 r with 4,800, 5,000 and 5,200 balls; for the crowd, the worst of 5 random spawns, by "
           "more than 10x: at the default 10 spawns made 0.03 to 0.6 m/s; for the pours, whose deepest "
           "overlap is one pair chaos places, by more than 10x: solver variants that changed a few "
           "contacts gave 0.000084 to 0.0013 r at 10k; for the gas, whose drift comes from whether "
           "one wall hit in 10,000 steps goes wrong, by more than 100x: at the default 5 spawns drifted "
           "0.00004 to 0.0022), or clearly cheaper and "
           "no less accurate; settings that end in the same state hash as another computed the same "
           "thing (the setting did not matter there) and never dominate each other. Bounce, cradle "
           "and stack are run several times per point and the cheapest run is kept. The front "
           "of fixed settings decides whether the default is on it; tolerance points "
           "(`tolerance=P`: `ballpit run --tolerance P`, the substeps chosen every step from the "
           "default's start, their column showing the mean and range used) are drawn as "
           "triangles and are on the front when no point at all dominates them. 'worst overlap "
           "after a step' is what a tolerance bounds, measured the same way for every point.\n",
           machine_line(points) + "\n",
           "![Pareto plot](speed_error.png)\n"]
    default_on_front = {}
    for c in cases:
        ps = sorted(by_case[c], key=lambda p: p["cost_ms_per_sim_s"])
        out.append(f"## {c}\n")
        out.append(f"Error: {ps[0]['error_metric']}. Spheres: {ps[0]['spheres']:,}. "
                   f"Threads: {ps[0].get('threads', '?')}.\n")
        settings = [(k, label) for k, label in SETTING_COLUMNS if any(k in p for p in ps)]
        header = (["setting"] + [label for _, label in settings] +
                  ["ms/step", "cost (ms/sim s)", "cost / default", "error"] +
                  [label for _, label in details_for(c)] + ["front", "state hash"])
        rows = []
        for p in ps:
            rows.append([("**default**" if p["point"] == "default" else p["point"])] +
                        [substeps_cell(p) if k == "substeps" else fmt(p.get(k)) for k, _ in settings] +
                        [fmt(p["ms_per_step"]), fmt(p["cost_ms_per_sim_s"]), fmt(p["cost_vs_default"]), fmt(p["error"])] +
                        [fmt(p.get(k)) for k, _ in details_for(c)] +
                        ["yes" if p["pareto"] else "", p["state_hash"]])
        out.append(md_table(header, rows))
        default = next((p for p in ps if p["point"] == "default"), None)
        if default:
            default_on_front[c] = default["pareto"]
            beaters = [p["point"] for p in ps if p["dominates_default"]]
            out.append(f"Default on the front: **{'yes' if default['pareto'] else 'no'}**" +
                       (f"; dominated by: {', '.join(beaters)}" if beaters else "") + ".\n")
            out.append(neighbours(default, ps))
        out.append(tolerance_lines(ps, default))

    out.append("## Summary: is the default on the Pareto front?\n")
    out.append(md_table(["case", "default on front", "default error", "default cost (ms/sim s)",
                         "settings that dominate the default"],
                        [[c, "yes" if default_on_front.get(c) else "no",
                          fmt(next(p["error"] for p in by_case[c] if p["point"] == "default")),
                          fmt(next(p["cost_ms_per_sim_s"] for p in by_case[c] if p["point"] == "default")),
                          ", ".join(p["point"] for p in by_case[c] if p["dominates_default"]) or "none"]
                         for c in cases if c in default_on_front]))
    # One default serves every case: the front that decides is the joint one.
    defaults = {c: p for c in cases for p in by_case[c] if p["point"] == "default"}
    labels = sorted({p["point"] for p in points if p["point"] != "default" and not is_tolerance(p)})
    better = []
    for label in labels:
        runs = {p["case"]: p for p in points if p["point"] == label}
        if jointly_dominates(runs, defaults):
            better.append(label)
    out.append(f"\nOne default serves every case, so the front that decides is the joint one: a setting "
               f"beats the default when in every case both ran it costs at most {COST_NOISE:.0%} more, "
               "is no less accurate and meets every bound the default meets (or computed the same state), "
               "and in one case it is clearly better; in " + " and ".join(EVENT_CASES) + " only cost and "
               "the bound count (their errors are single events, see the rule below). "
               f"Default on the joint front: **{'no' if better else 'yes'}**" +
               (f"; beaten by: {', '.join(better)}" if better else
                " (every setting that is better somewhere is worse, or dearer, somewhere else)") + ".\n")
    # The swept cases: those that ran the most fixed settings (pour-big runs only a few).
    fixed_labels = {c: {p["point"] for p in by_case[c] if not is_tolerance(p)} for c in cases}
    widest = max((len(v) for v in fixed_labels.values()), default=0)
    swept = [c for c in cases if len(fixed_labels[c]) == widest]
    out.append(choice_section(by_case, swept, COST_NOISE, ERROR_FLOOR, md_table, fmt))
    with open(a.md, "w") as f:
        f.write("\n".join(out))


if __name__ == "__main__":
    main()
