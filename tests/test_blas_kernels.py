"""What the docs show does not depend on the BLAS kernel: the same machine prints the same under each kernel.

OpenBLAS picks its kernels for the CPU; ``OPENBLAS_CORETYPE`` forces one (numpy's and scipy's OpenBLAS both
follow it, as threadpoolctl reports). Different kernels round differently: on this kind of machine the
five-bar's failed Newton took 26 to 28 iterations and its refined singular points came out 3e-10 to 3e-09
from singular, and the Delta with horizontal rods finds 3 to 7 branches, its notes other residuals and
counts. Each run below reports the kernels it used, so that the test cannot pass by running one kernel
three times.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from test_docs_examples import RUNS, run_line
from test_readme import ROOT, TIMING, environment, matches


def cpu_flags() -> set[str]:
    """The CPU's feature flags (``/proc/cpuinfo``; empty where there is none)."""
    try:
        text = open("/proc/cpuinfo").read()
    except OSError:
        return set()
    return {f for line in text.splitlines() if line.startswith("flags") for f in line.split(":", 1)[1].split()}


#: kernels an x86-64 OpenBLAS can be forced to, those this CPU runs (a kernel whose instructions the CPU lacks
#: would stop the process: Haswell needs AVX2 and FMA, Sandybridge AVX); OpenBLAS reports ``Prescott`` as ``Katmai``
KERNELS = tuple(
    kernel
    for kernel, needs in (("Haswell", {"avx2", "fma"}), ("Sandybridge", {"avx"}), ("Prescott", {"pni"}))
    if needs <= cpu_flags()  # pni: SSE3
)
#: runs the CLI, then prints the OpenBLAS kernels that process used
CLI_REPORTING_KERNELS = """
import sys, threadpoolctl
from pinmob.cli import main
status = main(sys.argv[1:])
used = sorted({i["architecture"] for i in threadpoolctl.threadpool_info() if i["internal_api"] == "openblas"})
print("OpenBLAS kernels:", ", ".join(used))
sys.exit(status)
"""


def run_with_kernel(kernel: str, args: list[str]) -> tuple[list[str], str]:
    """(output lines, the kernel reported) of ``pinmob ARGS`` with ``OPENBLAS_CORETYPE=kernel``."""
    env = environment() | {"OPENBLAS_CORETYPE": kernel}
    out = subprocess.run(
        [sys.executable, "-c", CLI_REPORTING_KERNELS, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
        timeout=300,
    )
    *lines, used = out.stdout.splitlines()
    assert out.returncode == 0 and used.startswith("OpenBLAS kernels: "), out.stdout
    assert "," not in used, used  # one kernel for numpy's and scipy's OpenBLAS
    return lines, used.removeprefix("OpenBLAS kernels: ")


def test_the_five_bar_joint_path_prints_the_same_under_each_kernel():
    """The five-bar scan of docs/usage.md: a failed solve (its residuals, not its iteration count) and two refined
    singular points (``distance <= 1e-06``, not the round-off figure) print the same, timings aside."""
    example = next(
        e
        for b in RUNS
        for e in b.examples
        if e.name.startswith(
            "$ pinmob scan tests/data/fivebar/robot.yaml --from mot1=0,mot2=0 --to mot1=3,mot2=-3 -n 5"
        )
    )
    assert example.command is not None
    outputs, used = {}, {}
    for kernel in KERNELS:
        lines, used[kernel] = run_with_kernel(kernel, example.command[1:])
        outputs[kernel] = [TIMING.sub(r"\1T\2R\3", line) for line in lines]
    assert len(set(used.values())) == len(KERNELS), used
    first = outputs[KERNELS[0]]
    assert any("did not converge: residuals" in line for line in first) and "distance <= 1e-06" in first[-1], first
    for kernel in KERNELS[1:]:
        assert outputs[kernel] == first, (kernel, used[kernel])


@pytest.mark.parametrize("kernel", KERNELS)
def test_an_undecided_verdict_matches_the_docs_under_each_kernel(kernel, tmp_path, monkeypatch):
    """finite-mobility.md's Delta with horizontal rods: the notes' figures differ between kernels, their words
    and the verdicts do not (the comparison rule of ``tests/test_readme.py``)."""
    block = next(b for b in RUNS if "rods-horizontal" in b.examples[0].name)
    (example,) = block.examples
    monkeypatch.setenv("OPENBLAS_CORETYPE", kernel)
    for folder in ("tests", "examples"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    out = run_line(example, tmp_path)
    lines = out.stdout.splitlines()
    assert out.returncode == 0 and matches(example.expected, lines), "\n".join(lines)
