"""Issue 63: a table that a script makes from results files is committed as the script prints it
today. Here: issue 64's depletion table (reports/accuracy/depletion-table.md), made by
reports/accuracy/depletion_table.py from the JSON and JSONL files beside it. Standard library
only; no binary needed."""

import subprocess
import sys

from conftest import ROOT


def test_the_depletion_table_is_what_its_results_files_give():
    script = ROOT / "reports" / "accuracy" / "depletion_table.py"
    made = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, check=True
    ).stdout
    committed = (ROOT / "reports" / "accuracy" / "depletion-table.md").read_text()
    assert made == committed, (
        "reports/accuracy/depletion-table.md differs from its results files: run "
        "`python3 reports/accuracy/depletion_table.py > reports/accuracy/depletion-table.md`"
    )
