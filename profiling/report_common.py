"""Helpers shared by the profiling report scripts (run with /usr/bin/python3)."""
import json
import os
import platform


def load_jsonl(path):
    """One JSON object per line; other lines (tables, progress) are skipped."""
    out = []
    if not path or not os.path.exists(path):
        return out
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith("{"):
                out.append(json.loads(line))
    return out


def machine_line(_runs=None):
    """CPU model, core count and load average when the report was written: the runs share the
    machine with whatever else ran, and the load average says how much that was."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        with open("/proc/loadavg") as f:
            load = " / ".join(f.read().split()[:3])
    except OSError:
        load = "unknown"
    policy = os.environ.get("OMP_WAIT_POLICY", "unset (GNU default: spin, then sleep)")
    return (f"Machine: {model}, {os.cpu_count()} cores; load average (1 / 5 / 15 min) when the "
            f"report was written: {load}; OMP_WAIT_POLICY: {policy}.")


def md_table(header, rows):
    lines = ["| " + " | ".join(str(h) for h in header) + " |",
             "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join("" if c is None else str(c) for c in r) + " |")
    return "\n".join(lines) + "\n"
