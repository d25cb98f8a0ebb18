"""Peak memory per point of explicit runs on lattice storage: the shipped Lamb plate case
(3 surface layers, LPS with the shear factor, horizon 3.015 spacings) enlarged to two plate
sizes, 3 steps, each in its own process; the difference of the peaks over the difference of the
points is the memory a point costs, free of the interpreter's and the compiled kernels' share.
With and without VTU snapshots (the one written at the end), and the peaks the memory estimate
(``setup.estimate``) gives the same runs. One Markdown table row each (benchmarks/RESULTS.md).
Run from the repository root: ``python benchmarks/lattice_memory.py``."""

import json
import subprocess
import sys
import tempfile

#: plate sides (m) of the two runs: about 240 000 and 480 000 points
SIDES = (0.34, 0.48)


#: the shipped case the runs enlarge
CASE = "cases/lamb_plate.yaml"


def overrides(side: float, vtu: bool) -> list[str]:
    """The ``--set`` items of the plate of side ``side`` (m), 3 steps, no output but the
    summary and (``vtu``) the VTU snapshot at the end."""
    return [
        f"{key}={value}"
        for key, value in {
            "geometry.size": f"[{side},{side},0.002]",
            "actuators.pzt.center": f"[{side / 2},{side / 2}]",
            "discretization.storage": "lattice",
            "solver.steps": "3",
            "solver.time": "null",
            "output.plots": "false",
            "output.sensors": "{}",
            "output.lines": "{}",
            "output.planes": "{}",
            "output.pzt_sensors": "{}",
            "output.snapshot_times": "[]",
            "output.vtu": str(vtu).lower(),
            "analysis": "null",
        }.items()
    ]


def peak_bytes(side: float, vtu: bool) -> tuple[int, int]:
    """(points, peak RSS in bytes) of one shortened run in a fresh process."""
    out = tempfile.mkdtemp()
    command = [sys.executable, "-m", "peridyn", "run", CASE, "-o", out, "--json"]
    for item in overrides(side, vtu):
        command += ["--set", item]
    # a fresh parent per run, so that its children's peak is this run's alone
    wrapper = (
        "import resource, subprocess, sys; "
        "done = subprocess.run(sys.argv[1:], capture_output=True, text=True, check=True); "
        "print(done.stdout.strip()); print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    lines = subprocess.run(
        [sys.executable, "-c", wrapper, *command], capture_output=True, text=True, check=True
    )
    summary, peak_kib = lines.stdout.strip().rsplit("\n", 1)
    return int(json.loads(summary)["points"]), int(peak_kib) * 1024


def warm_kernels(side: float = SIDES[0]) -> None:
    """Run a plate of ``side`` (m) once, unmeasured: a first run compiles the kernels into numba's
    cache, and the compiler's memory would count in its peak (a run that finds them cached
    does not compile)."""
    peak_bytes(side, vtu=False)


def estimated_bytes(side: float, vtu: bool) -> float:
    """The peak bytes ``peridyn run`` estimates for the run (``setup.estimate``)."""
    from peridyn.io.case import load_case
    from peridyn.setup.estimate import estimate_case

    return estimate_case(load_case(CASE, overrides(side, vtu))).peak_bytes


def main() -> None:
    print("| snapshots | points | peak RSS (MB) | bytes a point (marginal) | estimate (MB; B a point) |")
    print("|---|---|---|---|---|")
    warm_kernels()
    for vtu in (False, True):
        (n0, p0), (n1, p1) = (peak_bytes(side, vtu) for side in SIDES)
        e0, e1 = (estimated_bytes(side, vtu) for side in SIDES)
        kind = "VTU at the end" if vtu else "none"
        print(
            f"| {kind} | {n0} / {n1} | {p0 / 1e6:.0f} / {p1 / 1e6:.0f} | {(p1 - p0) / (n1 - n0):.0f} "
            f"| {e0 / 1e6:.0f} / {e1 / 1e6:.0f}; {(e1 - e0) / (n1 - n0):.0f} |"
        )


if __name__ == "__main__":
    main()
