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


def divide_root(a, b, c, d, out):
    """Per element a division, a square root, a multiply and an add (compiled by the test)."""
    for i in range(out.size):
        out[i] = a[i] / b[i] + math.sqrt(c[i]) * d[i]


def real_times_complex(x, a, b, re, im):
    """Per element a real times a complex: numba promotes x to x + 0j (compiled by the test)."""
    for i in range(re.size):
        w = x[i] * complex(a[i], b[i])
        re[i] = w.real
        im[i] = w.imag


def _loop_ir(fn, *arrays) -> str:
    import numba
    compiled = numba.njit(error_model="numpy")(fn)
    compiled(*arrays)
    return "\n".join(compiled.inspect_llvm().values())


def test_count_program_counts_a_known_loop_by_kind():
    a = np.full(16, 4.0)
    program = kernels.count_program(_loop_ir(divide_root, a, a, a, a, np.empty(16)))
    assert (program.add, program.mul, program.div, program.sqrt, program.fma, program.by_zero, program.other) == (
        1, 1, 1, 1, 0, 0, 0)
    assert program.width in (2, 4, 8) and program.flops == 4


def test_count_program_counts_a_real_promoted_to_complex_apart():
    """x (a + bi) as numba computes it, (x + 0i)(a + bi): x a, x b, and 0 b, 0 a and the two
    additions of those products by zero."""
    a = np.full(16, 2.0)
    program = kernels.count_program(_loop_ir(real_times_complex, a, a, a, np.empty(16), np.empty(16)))
    assert (program.add, program.mul, program.by_zero) == (0, 2, 4)


def test_count_program_reads_literal_zeros_and_fma():
    """Per 4 angles: a multiply by -0.0 and an add of it, 0 - x, an FMA and a division (4 lanes)."""
    ir = ("vector.body:\n  %a = fmul <4 x double> %x, splat (double -0.000000e+00)\n"
          "  %b = fadd <4 x double> %y, %a\n  %c = fsub <4 x double> zeroinitializer, %b\n"
          "  %d = call <4 x double> @llvm.fma.v4f64(<4 x double> %c, <4 x double> %y, <4 x double> %y)\n"
          "  %e = fdiv <4 x double> %d, %y\n  %f = fadd <4 x double> %e, %y\n"
          "  %index.next = add nuw i64 %index, 4\n  br label %vector.body\nend:\n")
    assert kernels.count_program(ir) == kernels.Program(add=1, div=1, fma=1, by_zero=3, width=4)


def test_bound_is_the_larger_of_ports_and_divider():
    rates = kernels.UnitRates(div=1e9, sqrt=2e9, fma=1e10, add_mul=2e10, note="given")
    program = kernels.Program(add=100, mul=60, by_zero=40, fma=50, div=20, sqrt=4)
    b = kernels.bound(program, rates)
    assert b.port == pytest.approx(200 / 2e10 + 50 / 1e10)         # 15 ns
    assert b.divider == pytest.approx(20 / 1e9 + 4 / 2e9)          # 22 ns
    assert (b.seconds, b.limit) == (b.divider, "divider")
    b = kernels.bound(kernels.Program(add=1000, div=1), rates)
    assert (b.seconds, b.limit) == (pytest.approx(5e-8), "ports")


def test_bound_lines_state_each_kernels_program_and_the_models_ratio_to_the_sum_of_bounds():
    from kinetostat_validation.benchmark import bound_lines
    rates = kernels.UnitRates(div=1e9, sqrt=1e9, fma=1e10, add_mul=1e10, note="given")
    programs = {"motion": kernels.Program(add=100, div=5, width=4), "peaks": kernels.Program(mul=300, div=10, width=4)}
    bounds = {k: kernels.bound(p, rates) for k, p in programs.items()}           # 10 ns (ports), 30 ns (ports)
    row = dict(model="m", programs=programs, bounds=bounds, bound=4e-8, cpu=6e-8, ratio=1.5)
    text = "\n".join(bound_lines(dict(rates=rates, rows=[row], angles=1000, rounds=3,
                                      load=((1.0, 1.0, 1.0), (2.0, 2.0, 2.0)))))
    assert "| m | motion | 100 | 0 | 0 | 5 | 0 | 0 | 0 | 105 | 4 | 10.0 | 5.0 | 10.0 (ports) |  | |" in text
    assert "| m | peaks | 0 | 300 | 0 | 10 | 0 | 0 | 0 | 310 | 4 | 30.0 | 10.0 | 30.0 (ports) | 60.0 | 1.50 (bound 40.0) |" in text
    assert "a division 1.0 ns" in text and "1.00 1.00 1.00 before" in text


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
