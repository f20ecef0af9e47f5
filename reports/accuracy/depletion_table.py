"""Issue 64's table: the full-depletion and pinch-off voltages with their error bars against
grids with every interval divided into 4, from the results files beside this script:

  depletion-error.jsonl   `PARTS=4 NO_FINE_PINCH=1 cargo run --release -p hpge-validation
                          --example depletion_error` (one line per detector in detectors/)
  pinch-off-fine.jsonl    `cargo run --release -p hpge-validation --example pinch_off_fine --
                          DETECTOR DEPLETED_V PARTS LO_V HI_V` (one line per detector and PARTS)
  depletion-error.json    the runs' date, commit, machine and commands
  depletion-bench.json    `cargo bench -p hpge-benches --bench bench_main -- 'depletion/u_fd'` (criterion medians)

    python3 reports/accuracy/depletion_table.py > reports/accuracy/depletion-table.md

Prints the Markdown table and the count of rows whose error bar bounds the finer value.
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def lines(name):
    path = os.path.join(HERE, name)
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(x) for x in f if x.strip()]


def main():
    meta = json.load(open(os.path.join(HERE, "depletion-error.json")))
    fine = {}
    for r in lines("pinch-off-fine.jsonl"):
        name = os.path.basename(r["detector"])
        fine.setdefault(name, {})[r["parts"]] = r
    rows, bounded, total = [], 0, 0
    used_fine = []
    for d in lines("depletion-error.jsonl"):
        name = d["detector"]
        e = d.get("u_fd_estimate")
        if e is None:
            rows.append(f"| {name} | not depleted below 6000 V | | | | | | | |")
            continue
        diff = abs(e["voltage_v"] - d["u_fd_fine4_V"])
        ok = diff <= e["err_v"]
        bounded += ok
        total += 1
        cells = [
            name,
            f"{e['voltage_v']:.2f} +- {e['err_v']:.2f}",
            f"{d['u_fd_fine4_V']:.2f}",
            f"{diff:.2f}",
            "yes" if ok else "**no**",
        ]
        pinch = [p for p in d.get("pinch_off", []) if p["grid"] == "reference"]
        if pinch and pinch[0]["estimate"]:
            p = pinch[0]["estimate"]
            ref = fine.get(name, {}).get(4) or fine.get(name, {}).get(2)
            cells.append(f"{p['voltage_v']:.2f} +- {p['err_v']:.2f} ({pinch[0]['seconds']:.0f} s)")
            if ref:
                used_fine.append((name, ref))
            if ref and ref["bracketed"]:
                # The finer value lies in (lo_V, hi_V]; a bracket wider than the bisection's
                # 1e-4 (a run given WIDTH_V) is shown as such and its far end is the diff.
                lo, hi = ref.get("lo_V", ref["pinch_off_V"]), ref["pinch_off_V"]
                pdiff = max(abs(p["voltage_v"] - lo), abs(p["voltage_v"] - hi))
                pok = pdiff <= p["err_v"]
                bounded += pok
                total += 1
                value = (
                    f"{hi:.2f}"
                    if hi - lo <= 1e-3 * hi
                    else f"({lo:.2f}, {hi:.2f}]"
                )
                cells += [
                    f"{value} ({ref['parts']}x, {ref['nodes']} nodes)",
                    f"{pdiff:.2f}" if hi - lo <= 1e-3 * hi else f"<= {pdiff:.2f}",
                    "yes" if pok else "**no**",
                ]
            elif ref:
                cells += [f"not in [{ref['pinch_off_V'] or 'bracket'}]", "", "no bracket"]
            else:
                cells += ["not run", "", ""]
        else:
            cells += ["no pocket", "", "", ""]
        rows.append("| " + " | ".join(cells) + " |")
    print(
        f"Made {meta['date']} with commit {meta['commit']} ({meta['machine']}); "
        f"solver revision \"{meta['solver_revision']}\"; default settings (tolerance 0.2%).\n"
    )
    print(
        "| detector | U_fd +- err (V) | U_fd, 4x finer | \\|diff\\| | bounded | "
        "pinch-off +- err (V) (search time) | pinch-off, finer grid | \\|diff\\| | bounded |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(r)
    print(f"\nError bars that bound the finer grid's value: {bounded} of {total}.")
    if used_fine:
        print("\nThe pinch-off's finer-grid values (`pinch-off-fine.jsonl`, the last line of each detector):\n")
        for name, ref in used_fine:
            made = ref.get("made")
            when = (
                f"made {made['date']} under the solver revision \"{made['solver_revision']}\""
                if made
                else "no date or revision recorded (made before the runs recorded them)"
            )
            lo = f"{ref['lo_V']:.3f}" if "lo_V" in ref else "n/a"
            print(
                f"- {name}: {ref['parts']}x ({ref['nodes']} nodes), the pinch-off in "
                f"({lo}, {ref['pinch_off_V']:.3f}] V, {ref['seconds']:.0f} s; {when}"
            )
    bench_file = os.path.join(HERE, "depletion-bench.json")
    if os.path.exists(bench_file):
        b = json.load(open(bench_file))
        print(
            f"\nCriterion benchmark of U_fd with its error bar on the reference grid "
            f"(`{b['command']}`; {b['date']}, commit {b['commit']}; {b['machine']}):\n"
        )
        print("| detector | median time (s) |")
        print("|---|---|")
        for name, t in b["median_s"].items():
            print(f"| {name} | {t:.3f} |")


if __name__ == "__main__":
    main()
