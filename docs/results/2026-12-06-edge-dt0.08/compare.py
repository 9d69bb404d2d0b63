#!/usr/bin/env python3
"""The black 50-line edge study at dt = 0.08 t_n against the same 50 seeds at dt = 0.04 t_n.

    /usr/bin/python3 compare.py [NEW_DIR [OLD_DIR [OUT_DIR [OLD_LABEL NEW_LABEL]]]]
        (defaults: black, the issue-17 edge50/black_k0.03, this folder, "dt = 0.04 t_n" "dt = 0.08 t_n")

Both studies ran the same command on the same 50 realization seeds (run.seed = 7), so each line
has a partner: the only difference is the time step. Compared:
  - the 10-90 % front and back edge widths with their 95 % bootstrap intervals (the issue's test:
    the intervals overlap);
  - per line, paired: printed toner, the first and last covered bin of the analysis range (where the
    line starts and ends on the drum), and the covered length; mean paired difference with its
    standard error, and the Wilcoxon signed-rank p-value (scipy, if present);
  - the two average coverage curves in one figure (compare.png).
Writes compare.json and compare.png into OUT_DIR (../2026-12-06-edge-sorted uses it for its own pair).
"""
import csv
import json
import math
import os
import sys
import warnings

here = os.path.dirname(os.path.abspath(__file__))
new_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "black")
old_dir = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "..", "2026-12-05-calibrated-chapter5", "edge50", "black_k0.03")
out_dir = os.path.abspath(sys.argv[3]) if len(sys.argv) > 3 else here
OLD_LABEL, NEW_LABEL = (sys.argv[4], sys.argv[5]) if len(sys.argv) > 5 else ("dt = 0.04 t_n", "dt = 0.08 t_n")
LINE0, LINE1, MARGIN = 100.0, 250.0, 300.0  # um, the study's --line-start, end and --margin
LO, HI = LINE0 - MARGIN, LINE1 + MARGIN


def study_json(d):
    # the study's JSON sits beside its folder (run.sh: black.json) or inside it (older layout)
    for p in (d.rstrip("/") + ".json", os.path.join(d, "edge-sharpness.json")):
        if os.path.exists(p):
            with open(p) as f:
                try:
                    return json.load(f)
                except json.JSONDecodeError:
                    continue
    return None


def lines(d):
    out = {}
    with open(os.path.join(d, "lines.csv")) as f:
        for row in csv.DictReader(f):
            if row["ok"] != "1":
                continue
            bins = [float(s) for s in row["covered_bin_starts_um"].split(";") if s]
            inside = [b for b in bins if LO <= b < HI]
            out[row["seed"]] = {
                "printed": int(row["printed"]),
                "first_um": min(inside) if inside else math.nan,
                "last_um": max(inside) if inside else math.nan,
                "covered_um": 2.625 * len(inside),
                "wall_s": float(row["wall_s"]),
            }
    return out


def mean_se(x):
    x = [v for v in x if not math.isnan(v)]
    n = len(x)
    m = sum(x) / n
    s = math.sqrt(sum((v - m) ** 2 for v in x) / (n - 1)) if n > 1 else math.nan
    return m, s / math.sqrt(n), n


def main():
    a, b = lines(old_dir), lines(new_dir)
    common = sorted(set(a) & set(b))
    res = {"old": os.path.relpath(old_dir, out_dir), "new": os.path.relpath(new_dir, out_dir), "paired_lines": len(common), "per_line": {}}
    try:
        from scipy.stats import wilcoxon
    except ImportError:
        wilcoxon = None
    for key in ("printed", "first_um", "last_um", "covered_um"):
        pairs = [(a[s][key], b[s][key]) for s in common if not (math.isnan(a[s][key]) or math.isnan(b[s][key]))]
        d = [y - x for x, y in pairs]
        m_old, se_old, _ = mean_se([x for x, _ in pairs])
        m_new, se_new, _ = mean_se([y for _, y in pairs])
        md, sed, n = mean_se(d)
        entry = {"n": n, "old_mean": m_old, "old_se": se_old, "new_mean": m_new, "new_se": se_new, "diff_mean": md, "diff_se": sed}
        if wilcoxon and n >= 10 and any(v != 0 for v in d):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # ties and zero differences: the normal approximation
                entry["wilcoxon_p"] = float(wilcoxon(d).pvalue)
        res["per_line"][key] = entry
    ja, jb = study_json(old_dir), study_json(new_dir)
    if ja and jb:
        for edge in ("front", "back"):
            ia, ib = ja[f"edge_{edge}_ci_m"], jb[f"edge_{edge}_ci_m"]
            res[f"edge_{edge}"] = {
                "old_um": 1e6 * ja[f"edge_{edge}_m"], "old_ci_um": [1e6 * v for v in ia],
                "new_um": 1e6 * jb[f"edge_{edge}_m"], "new_ci_um": [1e6 * v for v in ib],
                "intervals_overlap": ia[0] <= ib[1] and ib[0] <= ia[1],
            }
        res["printed_total"] = {"old": ja["printed_particles"], "new": jb["printed_particles"]}
    tmp = os.path.join(out_dir, "compare.json.tmp")
    with open(tmp, "w") as f:
        json.dump(res, f, indent=1)
    os.replace(tmp, os.path.join(out_dir, "compare.json"))
    print(json.dumps(res, indent=1))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for d, label, st in ((old_dir, OLD_LABEL, "-"), (new_dir, NEW_LABEL, "--")):
        p = os.path.join(d, "coverage_average.csv")
        if not os.path.exists(p):
            continue
        with open(p) as f:
            rows = list(csv.DictReader(f))
        x = [1e6 * float(r["x_m"]) for r in rows]
        ax.plot(x, [float(r["coverage"]) for r in rows], st, lw=1, label=label + " (average of the lines)")
        ax.plot(x, [float(r["fit"]) for r in rows], st, lw=2, alpha=0.6, label=label + " (sigmoid fit)")
    ax.axvspan(LINE0, LINE1, color="0.9", label="drum at 40 V")
    ax.set_xlabel("position on the drum s [um]")
    ax.set_ylabel("coverage")
    ax.set_title(f"Black, 50 lines, same seeds ({len(common)} pairs)")
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "compare.png.tmp.png"), dpi=120)
    os.replace(os.path.join(out_dir, "compare.png.tmp.png"), os.path.join(out_dir, "compare.png"))


if __name__ == "__main__":
    main()
