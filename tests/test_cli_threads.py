"""A command runs the BLAS of NumPy and SciPy on one thread, though it loads them only when it runs."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_PROBE = """
import sys
from workbook.cli.main import main
assert "numpy" not in sys.modules, "numpy was loaded before the command ran"
code = main(sys.argv[1:])
from threadpoolctl import threadpool_info
print("THREADS", max(library["num_threads"] for library in threadpool_info()))
sys.exit(code)
"""


def test_a_command_loads_its_blas_on_one_thread(tmp_path):
    """Without a thread count in the environment, OpenBLAS would start one thread per core, and a limit set
    before NumPy is loaded would not reach it: the command's BLAS must still run on one thread."""
    environment = {name: value for name, value in os.environ.items()
                   if name not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    environment["PYTHONPATH"] = str(ROOT)
    done = subprocess.run([sys.executable, "-c", _PROBE, "template", str(tmp_path / "case.xlsx")], cwd=tmp_path,
                          env=environment, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "case.xlsx").is_file()
    assert "THREADS 1" in done.stdout.splitlines()
