"""Tolerance studies: what the tolerances of a parametric model's parameters do to its forces.

    >>> import kinetostat
    >>> tol = kinetostat.tolerance("chain_unit_four_bar", {"r": 1e-4, "l": 2e-4}, samples=100, steps=36)
    >>> tol.outputs[-1], tol.linear.rss.shape, tol.monte_carlo.peak_quantiles.shape
    ('M_bal', (36, 5), (7, 5))

The outputs (K of them, `Tolerance.outputs`): every pair's |R_i_j| (N), M_bal (N m, signed; its
peak is max |M_bal|), a working machine's |F_bal| (N), at each of the N crank angles, and their
peaks over the cycle (max |value|); the reactions frictionless (FRICTION: friction's first
approximation, as `sensitivity` differentiates them).

- `linear`: first order, from the exact derivatives (`kinetostat.sensitivity`): per output and
  angle the worst case sum_p |dy/dp| t_p and the RSS sqrt(sum_p (dy/dp sigma_p)^2), and of each
  peak by the envelope rule (d peak/dp = sign(y) dy/dp at the nominal peak's angle; it assumes
  that angle is a unique maximum). A uniform +-t has sigma = t/sqrt(3); a normal sigma's "worst
  case" is the 3-sigma stack sum_p |dy/dp| 3 sigma_p.
- `contributions`: each tolerance's share (dy/dp sigma_p)^2 / sum of the output's first-order
  variance, at each angle and of each peak (the shares of an output sum to 1).
- `monte_carlo`: `samples` designs drawn (uniform within +-limits, or normal with those
  sigmas), run in chunks (`sweep`'s runner: in this process or on Dask), each chunk reduced
  inside: per design its peaks (exact quantiles of the peaks), per angle the count, sums and
  extremes and a histogram of BINS cells over a fixed range, from which the quantiles at each
  angle are read; memory grows with the designs, not with designs x angles.

Chunk invariance: the draws come in seed blocks of SEED_BLOCK samples, block b from
`SeedSequence(seed, spawn_key=(b,))` (SeedSequence(seed).spawn's b-th child), and every
reduction is exact (counts, extremes, histograms) or a fixed binary tree of sums over the seed
blocks (the moments: each chunk sums the aligned subtrees it holds, the caller the rest), so
results are identical bit for bit however the samples are split into chunks (a multiple of
SEED_BLOCK) and whichever scheduler runs them. The histograms' range is
fixed before the run from the first PILOT samples (their extremes widened by half their spread
on each side; a cell below and one above catch the rest, spanning to the exact extremes).

May use: sensitivity (the first order), sweep (the chunks' runner, the model's text, the force
columns, the quiet block, a design's failure reason), analysis, solve, fast, model, errors, units;
xarray only in `Tolerance.to_xarray` (through analysis' `_xarray`). Never the harness, the
engines, matplotlib or `kinetostat.report`.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .analysis import FRAME_NOTE, _labelled, _xarray, crank_angles
from .errors import AssemblyError, ModelError, StructureError
from .model import Mechanism, ParsedModel, _suggest, build, model_text, parse_text
from .solve import analyze
from .units import parameter_units

__all__ = ["tolerance", "Tolerance", "Linear", "MonteCarlo", "Contributions", "SEED_BLOCK", "CHUNK", "BINS",
           "QUANTILES", "DISTRIBUTIONS"]

#: Samples per seed block: the unit of the draws and of the per-angle moments (a chunk is a multiple of it).
SEED_BLOCK = 20
#: Samples per Dask task, by default.
CHUNK = 2000
#: Histogram cells per output and angle between the fixed range's ends (plus one below, one above).
BINS = 256
#: Samples whose extremes fix the histograms' range.
PILOT = 40
#: The quantiles reported, of the peaks and at each angle.
QUANTILES = (0.001, 0.01, 0.05, 0.5, 0.95, 0.99, 0.999)
#: The reactions of every design: the frictionless ones (friction's first approximation), as the derivatives'.
FRICTION = "first"
#: The distributions of the parameters: "uniform" within +-limit, "normal" with sigma = limit.
DISTRIBUTIONS = ("uniform", "normal")


@dataclass(frozen=True)
class Linear:
    """First order: the outputs at the nominal design and their derivatives' stacks."""
    nominal: np.ndarray            # (N, K) the outputs at the nominal design, N or N m
    derivative: np.ndarray         # (P, N, K) dy/dp, the output's unit per unit of p
    worst: np.ndarray              # (N, K) worst case sum_p |dy/dp| t_p (normal: t_p = 3 sigma_p)
    rss: np.ndarray                # (N, K) sqrt(sum_p (dy/dp sigma_p)^2): the first-order standard deviation
    peak: np.ndarray               # (K,) the nominal peak max |y| over the cycle
    peak_deg: np.ndarray           # (K,) the crank angle of the nominal peak, deg
    peak_derivative: np.ndarray    # (P, K) d peak/dp by the envelope rule
    peak_worst: np.ndarray         # (K,)
    peak_rss: np.ndarray           # (K,)


@dataclass(frozen=True)
class Contributions:
    """Each tolerance's share of each output's first-order variance (over p they sum to 1; NaN
    where the variance is 0)."""
    at_angle: np.ndarray           # (P, N, K)
    peak: np.ndarray               # (P, K)


@dataclass(frozen=True)
class MonteCarlo:
    """The sampled designs' outputs, reduced."""
    samples: int                   # designs drawn
    failed: int                    # designs that did not load, build or assemble (left out)
    first_error: str               # the failure of the first such design ('' where none)
    quantiles: tuple[float, ...]   # (Q,) the levels
    peaks: np.ndarray              # (samples, K) every design's peaks (NaN where it failed)
    peak_mean: np.ndarray          # (K,)
    peak_std: np.ndarray           # (K,) sample standard deviation (n - 1)
    peak_quantiles: np.ndarray     # (Q, K) exact (numpy's linear interpolation)
    count: np.ndarray              # (N, K) designs with a value there (not failed, not singular)
    mean: np.ndarray               # (N, K)
    std: np.ndarray                # (N, K) sample standard deviation (n - 1)
    min: np.ndarray                # (N, K) exact
    max: np.ndarray                # (N, K) exact
    quantile: np.ndarray           # (Q, N, K) from the histogram, linear within its cell
    quantile_error: np.ndarray     # (Q, N, K) the width of that cell: the exact sample quantile lies in it


@dataclass(frozen=True)
class Tolerance:
    """The result of `tolerance` (P parameters, N angles, K outputs)."""
    mechanism: str
    params: tuple[str, ...]        # (P,)
    values: np.ndarray             # (P,) nominal values, model units
    limits: np.ndarray             # (P,) +-limits (uniform) or sigmas (normal), model units
    sigma: np.ndarray              # (P,) the standard deviations, model units
    units: tuple[str, ...]         # (P,) the parameters' units
    dist: str
    seed: int
    phi_deg: np.ndarray            # (N,) deg
    outputs: tuple[str, ...]       # (K,) R_i_j, M_bal[, F_bal]
    output_units: tuple[str, ...]  # (K,) N or N m
    linear: Linear
    contributions: Contributions
    monte_carlo: MonteCarlo

    def __repr__(self) -> str:
        return (f"Tolerance(mechanism={self.mechanism!r}, params={self.params}, dist={self.dist!r}, "
                f"samples={self.monte_carlo.samples}, positions={len(self.phi_deg)}, outputs={len(self.outputs)})")

    def table(self):
        """One row per output's peak (pandas DataFrame, attrs["units"] per column): the nominal
        peak and its angle, the first-order worst case and RSS, the Monte Carlo mean, standard
        deviation and quantiles (q<level>), and each parameter's share (share_<p>, 1)."""
        import pandas as pd
        lin, mc = self.linear, self.monte_carlo
        cols: dict[str, Any] = {"output": list(self.outputs), "unit": list(self.output_units), "nominal": lin.peak,
                                "peak_deg": lin.peak_deg, "linear_worst": lin.peak_worst, "linear_rss": lin.peak_rss,
                                "mc_mean": mc.peak_mean, "mc_std": mc.peak_std}
        cols.update({_level(q): mc.peak_quantiles[n] for n, q in enumerate(mc.quantiles)})
        cols.update({f"share_{p}": self.contributions.peak[n] for n, p in enumerate(self.params)})
        df = pd.DataFrame(cols)
        value_unit = " or ".join(dict.fromkeys(self.output_units))      # each row's in its column `unit`
        df.attrs.update(mechanism=self.mechanism, units={
            "output": "text", "unit": "text", "peak_deg": "deg", "nominal": value_unit,
            **{c: value_unit for c in ("linear_worst", "linear_rss", "mc_mean", "mc_std")},
            **{_level(q): value_unit for q in mc.quantiles}, **{f"share_{p}": "1" for p in self.params}})
        return df

    def to_xarray(self):
        """Every result as an xarray Dataset (the optional extra: pip install 'kinetostat[xarray]'),
        dims param, phi (deg), quantile, sample; one variable per output and figure:
        <out>_nominal, _linear_worst, _linear_rss, _mc_mean, _mc_std, _mc_min, _mc_max, _mc_count
        (phi); <out>_mc_quantile, _mc_quantile_error (quantile, phi); <out>_derivative,
        _contribution (param, phi); <out>_peak (sample: each design's); with attrs units."""
        xr = _xarray()
        lin, mc, sh = self.linear, self.monte_carlo, self.contributions
        data = {}
        for k, (name, unit) in enumerate(zip(self.outputs, self.output_units)):
            per = [f"{unit} / {u}" if u not in ("1", "not stated") else unit for u in self.units]
            data.update({
                f"{name}_nominal": _labelled("phi", lin.nominal[:, k], unit, "none", f"{name} at the nominal design"),
                f"{name}_linear_worst": _labelled("phi", lin.worst[:, k], unit, "none", f"first-order worst case of {name}"),
                f"{name}_linear_rss": _labelled("phi", lin.rss[:, k], unit, "none", f"first-order RSS of {name}"),
                f"{name}_mc_mean": _labelled("phi", mc.mean[:, k], unit, "none", f"Monte Carlo mean of {name}"),
                f"{name}_mc_std": _labelled("phi", mc.std[:, k], unit, "none", f"Monte Carlo std of {name}"),
                f"{name}_mc_min": _labelled("phi", mc.min[:, k], unit, "none", f"Monte Carlo least {name}"),
                f"{name}_mc_max": _labelled("phi", mc.max[:, k], unit, "none", f"Monte Carlo largest {name}"),
                f"{name}_mc_count": _labelled("phi", mc.count[:, k].astype(float), "1", "none",
                                              f"designs with a value of {name}"),
                f"{name}_mc_quantile": _labelled(("quantile", "phi"), mc.quantile[:, :, k], unit, "none",
                                                 f"Monte Carlo quantiles of {name} (histogram of {BINS} cells)"),
                f"{name}_mc_quantile_error": _labelled(("quantile", "phi"), mc.quantile_error[:, :, k], unit, "none",
                                                       f"bound on the error of {name}_mc_quantile (its cell's width)"),
                f"{name}_derivative": _labelled(("param", "phi"), lin.derivative[:, :, k], "varies", "none",
                                                f"d {name} / d param", units_per_param=", ".join(per)),
                f"{name}_contribution": _labelled(("param", "phi"), sh.at_angle[:, :, k], "1", "none",
                                                  f"share of each tolerance in the first-order variance of {name}"),
                f"{name}_peak": _labelled("sample", mc.peaks[:, k], unit, "none",
                                          f"each sampled design's max |{name}| over the cycle")})
        coords = {"param": _labelled("param", list(self.params), "text", "none", "the toleranced parameters"),
                  "phi": _labelled("phi", self.phi_deg, "deg", "world", "crank angle"),
                  "quantile": _labelled("quantile", np.array(self.monte_carlo.quantiles), "1", "none", "level")}
        return xr.Dataset(data, coords=coords, attrs={
            "mechanism": self.mechanism, "dist": self.dist, "seed": self.seed, "samples": mc.samples,
            "failed": mc.failed, "params": ", ".join(self.params),
            "limits": ", ".join(f"{p}: {t:g} {u}" for p, t, u in zip(self.params, self.limits, self.units)),
            "conventions": f"outputs |R_i_j|, |F_bal| (N) and signed M_bal (N m); {FRAME_NOTE}"})


def _level(q: float) -> str:
    return f"q{q:g}"


def tolerance(model: str | Path | Mechanism, limits: Mapping[str, float], *, samples: int = 10_000, seed: int = 0,
              dist: str = "uniform", steps: int = 360, phi_deg=None, scheduler: Any = None,
              chunk: int = CHUNK, progress: bool = False) -> Tolerance:
    """The tolerance study of `model` (a file, a bundled model's name, or a Mechanism read from a
    file) for `limits` (parameter -> +-limit for dist="uniform", or sigma for "normal"; model
    units) at `steps` crank angles over a cycle or at `phi_deg` (deg): first order from the exact
    derivatives, and `samples` Monte Carlo designs drawn with `seed`, in chunks of `chunk`
    samples (a multiple of SEED_BLOCK) run as `sweep` runs them (`scheduler`: None in this
    process, "threads", "processes", a distributed scheduler's address or a Client).

    ValueError names an unknown parameter, a limit that is not a positive finite number, a bad
    `dist`, `samples`, `seed` or `chunk`; ModelError where the model does not load;
    ConnectionError: no distributed scheduler at the address."""
    from .sweep import _model_text, _peak_columns, _run
    text, source, base = _model_text(model)
    names, limit = _limits(base, limits)
    if dist not in DISTRIBUTIONS:
        raise ValueError(f"dist: expected {' or '.join(map(repr, DISTRIBUTIONS))}, got {dist!r}")
    _count("samples", samples, 1)
    _count("seed", seed, 0)
    _count("chunk", chunk, 1)
    if chunk % SEED_BLOCK:
        raise ValueError(f"chunk: expected a multiple of SEED_BLOCK ({SEED_BLOCK}) samples, got {chunk}")
    phi_deg = crank_angles(phi_deg, steps)
    sigma = limit / math.sqrt(3) if dist == "uniform" else limit
    nominal = np.array([float(base.parameters[n]) if n != "g" else base.g for n in names])
    model = parse_text(text, source)
    pinned = build(model, parameters=dict(zip(names, map(float, nominal))))   # as every sample sets them
    lin, shares = _linear(pinned, names, phi_deg, limit if dist == "uniform" else 3 * limit, sigma)
    from . import fast
    spec = _Spec(names, nominal, limit, dist, seed, phi_deg, fast.pays(base, samples * len(phi_deg), "full"),
                 lin.nominal)
    pilot = _outputs(model, spec, range(min(PILOT, samples)))[0]
    spec = _with_range(spec, pilot)
    parts = [range(a, min(a + chunk, samples)) for a in range(0, samples, chunk)]
    results = _run(parts, functools.partial(_chunk, text, source, spec), scheduler, progress, "tolerance")
    outputs = [name.removeprefix("peak_") for name in _peak_columns(base)]
    return Tolerance(base.name, tuple(names), spec.nominal, limit, sigma, tuple(_units(base, names)), dist, seed,
                     phi_deg, tuple(outputs), tuple("N m" if o == "M_bal" else "N" for o in outputs), lin, shares,
                     _monte_carlo(results, samples, spec))


# ----------------------------------------------------------------------------- inputs

def _count(name: str, x: Any, least: int) -> None:
    if not isinstance(x, (int, np.integer)) or isinstance(x, bool) or x < least:
        raise ValueError(f"{name}: expected a whole number >= {least}, got {x!r}")


def _limits(base: Mechanism, limits: Mapping[str, float]) -> tuple[list[str], np.ndarray]:
    """The toleranced parameters and their limits: ValueError naming an unknown parameter or a
    limit that is not a positive finite number."""
    valid = [*base.parameters, "g"]
    if not limits:
        raise ValueError("tolerance: no parameter given a tolerance")
    for name, t in limits.items():
        if name not in valid:
            raise ValueError(f"tolerance: {name!r} is not a parameter of the model{_suggest(name, valid)}. "
                             f"Parameters: {', '.join(valid)}")
        if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)) or not (
                math.isfinite(t) and t > 0):
            raise ValueError(f"tolerance: {name}: expected a positive finite limit, got {t!r}")
    return list(limits), np.array([float(t) for t in limits.values()])


def _units(base: Mechanism, names: list[str]) -> list[str]:
    stated = {**parameter_units(base, model_text(base)), "g": "m/s^2"}
    return [stated[n] for n in names]


# ----------------------------------------------------------------------------- first order

def _linear(base: Mechanism, names: list[str], phi_deg: np.ndarray, t: np.ndarray,
            sigma: np.ndarray) -> tuple[Linear, Contributions]:
    """The first-order stacks from `kinetostat.sensitivity` at the nominal design `base`, loaded
    with the toleranced parameters set, as each sample sets them (so that d/dr holds a toleranced
    l = sqrt(r**2 + c**2) fixed, as the samples do; an untoleranced one follows r). `t`: the
    worst-case half widths, `sigma`: the standard deviations, each (P,)."""
    from .sensitivity import sensitivity
    sens = sensitivity(base, params=names, steps=len(phi_deg), phi_deg=phi_deg)
    res = sens.result
    R = res.forces.R                                  # (N, n_pairs, 2)
    nominal = _values(base, res)
    D = np.empty((len(names),) + nominal.shape)
    for n, p in enumerate(names):
        cols = [_magnitude_derivative(R[:, k], sens.reaction(*pair.links)[p]) for k, pair in enumerate(base.pairs)]
        cols.append(np.asarray(sens.balancing_moment[p], float))
        if base.drive.kind == "machine":
            cols.append(_magnitude_derivative(res.forces.F_bal, sens.balancing_force[p]))
        D[n] = np.stack(cols, axis=-1)
    return first_order(nominal, D, phi_deg, t, sigma)


def _magnitude_derivative(z: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """d|z|/dp = (z . dz/dp) / |z| of (N, 2) vectors (NaN where |z| = 0: no derivative)."""
    mag = np.linalg.norm(z, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(mag > 0, np.sum(z * dz, axis=-1) / mag, np.nan)


def first_order(nominal: np.ndarray, D: np.ndarray, phi_deg: np.ndarray, t: np.ndarray,
                sigma: np.ndarray) -> tuple[Linear, Contributions]:
    """The worst case, RSS and shares of outputs `nominal` (N, K) with derivatives `D` (P, N, K):
    at each angle and of each peak (max |y|, its derivative by the envelope rule at the nominal
    peak's angle). `t`, `sigma`: (P,) the half widths of the worst case and the standard deviations."""
    at = np.nanargmax(np.abs(np.where(np.isnan(nominal), -np.inf, nominal)), axis=0)     # (K,)
    K = np.arange(nominal.shape[1])
    peak = np.abs(nominal[at, K])
    dpeak = np.sign(nominal[at, K]) * D[:, at, K]                   # (P, K)
    var = (D * sigma[:, None, None]) ** 2
    pvar = (dpeak * sigma[:, None]) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        shares = Contributions(var / var.sum(axis=0), pvar / pvar.sum(axis=0))
    lin = Linear(nominal, D, np.abs(D * t[:, None, None]).sum(axis=0), np.sqrt(var.sum(axis=0)), peak,
                 np.asarray(phi_deg, float)[at], dpeak, np.abs(dpeak * t[:, None]).sum(axis=0), np.sqrt(pvar.sum(axis=0)))
    return lin, shares


def _values(mech: Mechanism, res) -> np.ndarray:
    """The outputs of the analysis `res` of `mech` at each angle, (N, K): |R_i_j| of every pair,
    M_bal, a machine's |F_bal| (`sweep`'s force columns)."""
    from .sweep import _peak_columns
    return np.stack([np.asarray(col(res), float) for col in _peak_columns(mech).values()], axis=-1)


# ----------------------------------------------------------------------------- the Monte Carlo chunks

@dataclass(frozen=True)
class _Spec:
    """What every chunk needs besides the model's text (plain, picklable)."""
    names: list[str]
    nominal: np.ndarray          # (P,)
    limit: np.ndarray            # (P,)
    dist: str
    seed: int
    phi_deg: np.ndarray          # (N,)
    compiled: bool               # the compiled kernel (decided once for the whole run)
    centre: np.ndarray           # (N, K) the nominal outputs: the moments are summed about them
    lo: np.ndarray | None = None  # (N, K) the histograms' range
    hi: np.ndarray | None = None


def _with_range(spec: _Spec, pilot: np.ndarray) -> _Spec:
    """`spec` with the histograms' range: the pilot's extremes (n, N, K) widened by half their
    spread on each side (a spread of 0 or none: 1e-9 of the nominal's size, at least 1e-12)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)          # an angle singular in every pilot design
        lo, hi = np.nanmin(pilot, axis=0), np.nanmax(pilot, axis=0)
    centre = np.where(np.isfinite(lo), (lo + hi) / 2, np.nan_to_num(spec.centre))
    half = np.where(np.isfinite(lo) & (hi > lo), hi - lo, np.maximum(1e-9 * np.abs(centre), 1e-12))
    return _Spec(**{**spec.__dict__, "lo": centre - half, "hi": centre + half})


def _draws(spec: _Spec, part: range) -> np.ndarray:
    """The parameter values (len(part), P) of the samples `part`: seed block b (SEED_BLOCK samples)
    drawn from SeedSequence(seed, spawn_key=(b,)), whole, so that sample i's values are the same
    in any chunk."""
    first, last = part.start // SEED_BLOCK, (part.stop - 1) // SEED_BLOCK
    P = len(spec.names)
    z = []
    for b in range(first, last + 1):
        rng = np.random.default_rng(np.random.SeedSequence(spec.seed, spawn_key=(b,)))
        z.append(rng.uniform(-1.0, 1.0, (SEED_BLOCK, P)) if spec.dist == "uniform"
                 else rng.standard_normal((SEED_BLOCK, P)))
    z = np.concatenate(z)[part.start - first * SEED_BLOCK:part.stop - first * SEED_BLOCK]
    return spec.nominal + z * spec.limit


def _outputs(model: ParsedModel, spec: _Spec, part: range) -> tuple[np.ndarray, int, str]:
    """The outputs (len(part), N, K) of the samples `part` of the parsed `model` (NaN for a design
    that does not load, build or assemble), how many failed and the first one's reason ('')."""
    from .sweep import _kernel, _quiet, _reason
    values = _draws(spec, part)
    y: dict[int, np.ndarray] = {}
    errors: dict[int, Exception] = {}
    built: dict[int, Mechanism] = {}
    with _quiet():
        for n, row in enumerate(values):
            try:
                mech = build(model, parameters=dict(zip(spec.names, map(float, row))))
                if _kernel(mech, spec.compiled, FRICTION):
                    built[n] = mech
                else:
                    y[n] = _values(mech, analyze(mech, phi_deg=spec.phi_deg, friction=FRICTION))
            except (ModelError, StructureError, AssemblyError) as exc:
                errors[n] = exc
        compiled, failed = _compiled(built, spec.phi_deg)
    y.update(compiled)
    errors.update(failed)
    out = np.full((len(values),) + spec.centre.shape, np.nan)
    for n, v in y.items():
        out[n] = v
    first = f"sample {part.start + min(errors)}: {_reason(errors[min(errors)])}" if errors else ""
    return out, len(errors), first


def _compiled(built: Mapping[int, Mechanism], phi_deg: np.ndarray) -> tuple[dict[int, np.ndarray], dict[int, Exception]]:
    """The outputs of the designs `built` (sample -> Mechanism) by the compiled kernel, together
    (`fast.analyses`: a batch of designs per kernel call, on this thread: the chunks are the parallel
    work); where one does not assemble, one by one: the outputs, and the failures (sample -> AssemblyError)."""
    from . import fast
    try:
        return {n: _values(m, res) for (n, m), res in zip(built.items(), fast.analyses(list(built.values()), phi_deg))}, {}
    except AssemblyError as exc:
        if len(built) == 1:
            return {}, {n: exc for n in built}
    out, failed = {}, {}
    for n, m in built.items():
        y, f = _compiled({n: m}, phi_deg)
        out.update(y)
        failed.update(f)
    return out, failed


@dataclass(frozen=True)
class _Part:
    """A chunk's reduction."""
    peaks: np.ndarray        # (n, K)
    moments: dict            # (level, index) -> (3, N, K): count, sum and sum of squares of y - centre over
                             # the seed blocks [index 2^level, (index + 1) 2^level), the chunk's largest such runs
    hist: np.ndarray         # (N, K, BINS + 2) counts: below the range, the cells, above it
    min: np.ndarray          # (N, K)
    max: np.ndarray          # (N, K)
    failed: int
    first_error: str


def _chunk(text: str, source: str, spec: _Spec, part: range) -> _Part:
    """The reduction of the samples `part` (whole seed blocks but the run's last), seed block by
    seed block, the text parsed once. A Dask task: plain, picklable arguments."""
    model = parse_text(text, source)
    N, K = spec.centre.shape
    peaks, leaves, failed, first = [], {}, 0, ""
    hist = np.zeros(N * K * (BINS + 2), np.int64)
    lo, hi = np.full((N, K), np.inf), np.full((N, K), -np.inf)
    cell = np.arange(N * K).reshape(N, K) * (BINS + 2)
    for a in range(part.start, part.stop, SEED_BLOCK):
        y, f, why = _outputs(model, spec, range(a, min(a + SEED_BLOCK, part.stop)))
        failed, first = failed + f, first or why
        ok = ~np.isnan(y)
        peaks.append(np.where(ok.any(axis=1), np.fmax.reduce(np.abs(y), axis=1), np.nan))
        d = np.where(ok, y - spec.centre, 0.0)
        leaves[(0, a // SEED_BLOCK)] = np.stack([ok.sum(axis=0).astype(float), d.sum(axis=0), (d * d).sum(axis=0)])
        lo, hi = np.fmin(lo, np.fmin.reduce(y, axis=0)), np.fmax(hi, np.fmax.reduce(y, axis=0))
        with np.errstate(invalid="ignore"):
            at = np.clip(np.floor((y - spec.lo) / (spec.hi - spec.lo) * BINS), -1, BINS)
        hist += np.bincount(np.broadcast_to(cell, y.shape)[ok] + at[ok].astype(np.int64) + 1, minlength=hist.size)
    blocks = (part.start // SEED_BLOCK, -(-part.stop // SEED_BLOCK))
    moments = {node: _tree(leaves, *node, blocks[1]) for node in _runs(*blocks)}
    return _Part(np.concatenate(peaks), moments, hist.reshape(N, K, BINS + 2), lo, hi, failed, first)


def _runs(first: int, stop: int) -> list[tuple[int, int]]:
    """The seed blocks [first, stop) as the fewest aligned runs (level, index): blocks
    [index 2^level, (index + 1) 2^level), each as long as it can be."""
    out = []
    while first < stop:
        level = 0
        while first % (2 << level) == 0 and first + (2 << level) <= stop:
            level += 1
        out.append((level, first >> level))
        first += 1 << level
    return out


def _tree(nodes: Mapping[tuple[int, int], np.ndarray], level: int, index: int, blocks: int) -> np.ndarray:
    """The sum over the seed blocks [index 2^level, (index + 1) 2^level) (those below `blocks`):
    a node given in `nodes`, else the sum of its two halves (the left alone where the right
    starts at `blocks` or beyond). The same tree of additions however the nodes were split."""
    if (level, index) in nodes:
        return nodes[(level, index)]
    left = _tree(nodes, level - 1, 2 * index, blocks)
    return left if (2 * index + 1) << (level - 1) >= blocks else left + _tree(nodes, level - 1, 2 * index + 1, blocks)


def _monte_carlo(parts: list[_Part], samples: int, spec: _Spec) -> MonteCarlo:
    """The chunks' reductions joined (in sample order: the same sums however they were split)."""
    peaks = np.concatenate([p.peaks for p in parts])
    blocks = -(-samples // SEED_BLOCK)
    n, s1, s2 = _tree({k: v for p in parts for k, v in p.moments.items()}, max(blocks - 1, 0).bit_length(), 0, blocks)
    hist = sum(p.hist for p in parts)
    lo = functools.reduce(np.fmin, [p.min for p in parts])
    hi = functools.reduce(np.fmax, [p.max for p in parts])
    import warnings
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)        # an output NaN in every design
        shift = s1 / n
        std = np.sqrt(np.maximum(s2 - s1 * shift, 0.0) / (n - 1))
        peak_q = np.nanquantile(peaks, QUANTILES, axis=0)
        peak_mean, peak_std = np.nanmean(peaks, axis=0), np.nanstd(peaks, axis=0, ddof=1)
    return MonteCarlo(samples, sum(p.failed for p in parts), next((p.first_error for p in parts if p.first_error), ""),
                      QUANTILES, peaks, peak_mean, peak_std, peak_q, n.astype(np.int64), shift, std, lo, hi,
                      *_hist_quantiles(hist, spec.lo, spec.hi, lo, hi))


def _hist_quantiles(hist: np.ndarray, lo: np.ndarray, hi: np.ndarray, least: np.ndarray,
                    most: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The QUANTILES (Q, N, K) from the histograms (N, K, BINS + 2) of the range [lo, hi] (N, K)
    and the samples' extremes `least`, `most` (the outer cells' far ends): the rank ceil(q n)'s
    cell, linear within it; and that cell's width, within which the exact order statistic
    x_(ceil(q n)) lies too (NaN where no design has a value)."""
    n = hist.sum(axis=-1)
    C = np.cumsum(hist, axis=-1)
    w = (hi - lo) / BINS
    edges = np.concatenate([least[..., None], lo[..., None] + w[..., None] * np.arange(BINS + 1), most[..., None]],
                           axis=-1)                                  # (N, K, BINS + 3)
    q_out, e_out = [], []
    for q in QUANTILES:
        r = np.maximum(np.ceil(q * n), 1)
        j = np.minimum((C < r[..., None]).sum(axis=-1), BINS + 1)[..., None]
        before = np.where(j > 0, np.take_along_axis(C, np.maximum(j - 1, 0), -1), 0)[..., 0]
        count = np.take_along_axis(hist, j, -1)[..., 0]
        left, right = np.take_along_axis(edges, j, -1)[..., 0], np.take_along_axis(edges, j + 1, -1)[..., 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            value = left + (r - before - 0.5) / count * (right - left)
        q_out.append(np.where(n > 0, value, np.nan))
        e_out.append(np.where(n > 0, right - left, np.nan))
    return np.stack(q_out), np.stack(e_out)
