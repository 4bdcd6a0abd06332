"""The benchmark's kernel timers do the real work (the driving moment of the engines' exact
routes) and the flop counter counts what a kernel computes. Their times are not asserted (the
benchmark prints them). numba is imported by the tests that compile (not at collection, which
every worker does)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat_validation import engine_mujoco, engine_pinocchio, kernels
from kinetostat_validation.scene import build_scene

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", params=["chain_unit_four_bar", "slotted_link_shaper"])
def scene(request):
    """A four-bar (revolute loop closure) and the shaper (a prismatic one), 12 angles."""
    return build_scene(kinetostat.load(ROOT / "models" / f"{request.param}.toml"), steps=12)


def _same_moment(k: kernels.KernelTiming, M: np.ndarray) -> None:
    assert np.isfinite(k.M_drive).sum() == np.isfinite(M).sum() > 0
    np.testing.assert_allclose(k.M_drive, M, rtol=0, atol=1e-12 * np.nanmax(np.abs(M)))


def test_mujoco_kernel_gives_the_exact_routes_moment(scene):
    k = kernels.mujoco_kernel(scene, repeat=1)
    _same_moment(k, engine_mujoco.solve(scene).M_drive)


def test_pinocchio_kernel_gives_the_exact_routes_moment(scene):
    k = kernels.pinocchio_kernel(scene, repeat=1)
    _same_moment(k, engine_pinocchio.solve(scene).M_drive)


def five_flops(x, y):
    """5 flops: a multiply, a divide, an add, a square root, a subtract (compiled by the test)."""
    return x * y + x / y - math.sqrt(x)


def test_count_flops_on_a_known_kernel():
    import numba
    known = numba.njit(five_flops)
    assert known(4.0, 2.0) == 8.0
    assert kernels.count_flops(known) == 5


def test_count_flops_ir_counts_vector_lanes_and_fma_twice():
    ir = ("B0:\n  %a = fmul fast <4 x double> %x, %y\n  %b = fadd double %p, %q\n"
          "  %c = call fast <2 x double> @llvm.fma.v2f64(<2 x double> %u, <2 x double> %v, <2 x double> %w)\n"
          "  %d = fcmp olt double %p, %q\n  ret void\n")
    assert kernels.count_flops_ir(ir) == 4 + 1 + 2 * 2


def test_count_flops_refuses_a_loop():
    import numba

    @numba.njit
    def total(a):
        s = 0.0
        for v in a:
            s += v
        return s
    total(np.ones(3))
    with pytest.raises(ValueError, match="per-angle body"):
        kernels.count_flops(total)


def test_machine_limit_is_the_slower_of_arithmetic_and_memory():
    rates = kernels.MachineRates(1e10, 1e9, "given")
    assert kernels.machine_limit(500, 100, rates=rates) == pytest.approx(1e-7)      # memory bound
    assert kernels.machine_limit(5000, 1, rates=rates) == pytest.approx(5e-7)       # arithmetic bound
    assert kernels.machine_limit(5000, 1, cores=2, rates=rates) == pytest.approx(2.5e-7)
    assert kernels.bytes_per_angle({"M": np.zeros(10), "R": np.zeros((10, 4, 2))}, 10) == 72.0


def test_count_flops_loop_counts_the_vector_body_per_iteration():
    """16 lanes of arithmetic in a vector.body that steps 8 angles: 2 flops per angle; the
    scalar remainder and the epilogue's vector loop are not the loop."""
    ir = ("entry:\n  br label %vector.body\n"
          "vector.body:                                      ; preds = %vector.body, %entry\n"
          "  %a = fmul <8 x double> %x, %y\n  %b = fadd <8 x double> %a, %y\n"
          "  %index.next = add nuw i64 %index, 8\n  br i1 %c, label %tail, label %vector.body\n"
          "vec.epilog.vector.body:\n  %e = fmul <4 x double> %x, %y\n  %index.next9 = add nuw i64 %index8, 4\n"
          "tail:\n  %s = fadd double %p, %q\n  ret void\n")
    assert kernels.count_flops_loop(ir) == 2.0
    with pytest.raises(ValueError, match="no vectorised loop"):
        kernels.count_flops_loop("entry:\n  %s = fadd double %p, %q\n  ret void\n")


def test_cpu_info_names_the_cpu_and_its_vector_flags():
    info = kernels.cpu_info()
    flags = next((ln.split(":", 1)[1].split() for ln in open("/proc/cpuinfo") if ln.startswith("flags")), [])
    assert ("avx2" in info["vector_flags"].split()) == ("avx2" in flags)
    assert ("avx512f" in info["vector_flags"].split()) == ("avx512f" in flags)
    assert info["model"] and info["llvm_target"] and len(info["load"].split()) == 3


@pytest.mark.slow   # the sensitivity kernel of the four-bar (compiled once per machine: minutes on a busy 2-core one)
def test_sensitivity_cost_times_the_plain_analysis_and_the_sensitivities():
    """The benchmark's issue-39 budget: one row for the plain compiled analysis (ratio 1) and one
    per count of parameters, the first p of the model's, with the budget (1 + 0.6 p) beside."""
    from kinetostat_validation.benchmark import sensitivity_cost, sensitivity_lines
    rows = sensitivity_cost(models=("chain_unit_four_bar",), angles=20_000, counts=(1,), rounds=1)
    assert [(r["p"], r["params"], r["budget"]) for r in rows] == [(0, [], 1.0), (1, ["r"], 1.6)]
    assert rows[0]["ratio"] == 1.0 and math.isfinite(rows[1]["ratio"]) and rows[1]["ratio"] > 0
    assert "| chain_unit_four_bar | 1 (r) |" in "\n".join(sensitivity_lines(rows))
