"""The argument parser of every command (`build_parser`): options, help texts, each command's
function.

May use: the command modules of this package and `.common` (argument types).
"""
from __future__ import annotations

import argparse

from .analyze import cmd_analyze, cmd_examples, cmd_export, cmd_schema, cmd_structure
from .common import NORMAL, QUIET, VERBOSE, _Parser, _angle, _coefficient, _inertia, _jobs, _positive, _steps
from .motion import cmd_motion
from .plans import _plan_names, _scale_item, cmd_page, cmd_plans, cmd_variant
from .report import cmd_report
from .sweep import _param, cmd_sweep
from .tolerance import _tol, cmd_tolerance
from .validate import cmd_validate


def _friction_option(parser: argparse.ArgumentParser, default: str) -> None:
    """--friction first|reactions, with what its default is for this command."""
    parser.add_argument("--friction", choices=["first", "reactions"], default=None,
                        help="a model with [friction]: 'first' (the first approximation: frictionless reactions) or "
                             f"'reactions' (friction in the reactions, exact); {default}")


def _law_options(parser: argparse.ArgumentParser, what: str) -> None:
    """--delta D | --flywheel J: `what` at the machine's true law of motion (`kinetostat motion`)."""
    g = parser.add_mutually_exclusive_group()
    g.add_argument("--delta", metavar="D", type=_coefficient,
                   help=f"{what} at the true law of motion omega(phi), eps(phi) with the smallest flywheel on the crank "
                        "shaft that holds the coefficient of fluctuation D = (omega_max - omega_min) / omega_mean, "
                        "0 < D < 2 (see 'kinetostat motion')")
    g.add_argument("--flywheel", metavar="J", type=_inertia,
                   help=f"{what} at the true law of motion with a flywheel of moment of inertia J (kg m^2) on the "
                        "crank shaft")


def _verbosity_options(parser: argparse.ArgumentParser, default) -> None:
    """-q/--quiet and -v/--verbose into `verbosity`; a command's own take `default`
    argparse.SUPPRESS, so that the ones given before the command stay."""
    g = parser.add_mutually_exclusive_group()
    g.add_argument("-q", "--quiet", dest="verbosity", action="store_const", const=QUIET, default=default,
                   help="errors only on stderr: no progress bar, information line or warning; no line saying "
                        "which files were written; results (tables, --out -) still go to stdout")
    g.add_argument("-v", "--verbose", dest="verbosity", action="store_const", const=VERBOSE, default=default,
                   help="also the progress lines on stderr: per model its analysis, each engine route of "
                        "validate, each variant, each chunk of a sweep (report says its first line and each "
                        "model's routes, figures, tables and plans without -v)")


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__
    from ..sweep import CHUNK
    p = _Parser(prog="kinetostat",
                description="Kinetostatic analysis of planar linkages (graphical-analytic method, computed "
                            "exactly over the crank cycle) and its cross-validation against physics engines.",
                epilog="Exit codes: 0 ok; 1 validate: a check failed (report: a model's report not made, or --check found a "
                       "difference); 2 bad input or options; 3 validate: "
                       "nothing failed but a model was not checked (or a route named with --engines is not "
                       "installed); 130 interrupted (Ctrl-C). "
                       "Bundled models ship inside the package ('kinetostat examples' lists them); "
                       "$KINETOSTAT_MODELS names another folder of *.toml models to use instead.")
    p.add_argument("--version", action="version", version=f"kinetostat {__version__}")
    _verbosity_options(p, NORMAL)
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    routes = "pinocchio, mujoco, mujoco-sim, pymunk, reference (40-digit mpmath, no engine); none: reference only"

    a = sub.add_parser("analyze", help="kinematics and kinetostatics of one model: summary and full table",
                       description="Analyse MODEL over the crank cycle (or at given angles): print a summary "
                                   "(structure formula, peak reaction of every pair and where, balancing moment "
                                   "range, lever discrepancy) and write the full table of res.to_frame().")
    a.add_argument("model", metavar="MODEL", help="model file (TOML, see models/FORMAT.md) or a bundled model's name")
    g = a.add_mutually_exclusive_group()
    g.add_argument("--at", metavar="DEG", nargs="+", type=_angle,
                   help="crank angles in degrees (model's reference and sense), e.g. --at 0 30 90")
    g.add_argument("--steps", metavar="N", type=_steps, default=360,
                   help="N equal steps over a revolution (default 360)")
    _friction_option(a, "default: the model's friction.method, else first")
    _law_options(a, "analyse")
    a.add_argument("--out", metavar="FILE",
                   help="write the full table: FILE.csv, FILE.parquet (needs pyarrow) or FILE.json "
                        "(records); '-' writes CSV to stdout and the summary to stderr")
    a.set_defaults(func=cmd_analyze)

    s = sub.add_parser("structure", help="mobility, Assur groups and structure formula of one model",
                       description="Structural analysis of MODEL: mobility W by Chebyshev's formula with its "
                                   "arithmetic, the Assur groups with their kinds, the structure formula.")
    s.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    s.add_argument("--modes", action="store_true", help="list every assembly mode of each triad at the design position")
    s.set_defaults(func=cmd_structure)

    e = sub.add_parser("export", help="write a model as MJCF (MuJoCo) or URDF for physics engines",
                       description="Write MODEL's links (mass, centre of mass, I_S), pairs and gravity as an "
                                   "engine model, from the scene the validation harness builds. --mjcf: the "
                                   "spanning tree with the loop-closing pairs as equality constraints and a "
                                   "keyframe 'phi0' (assembled at phi = 0). --urdf: the spanning tree only; URDF "
                                   "cannot express closed loops, so each loop-closing pair is written as an XML "
                                   "comment '<!-- loop closure ... -->' for you to add as a constraint. Loads, "
                                   "drive and friction are not exported.")
    e.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    fmt = e.add_mutually_exclusive_group(required=True)
    fmt.add_argument("--mjcf", dest="format", action="store_const", const="mjcf", help="MuJoCo MJCF")
    fmt.add_argument("--urdf", dest="format", action="store_const", const="urdf",
                     help="URDF of the spanning tree, loop closures as comments")
    e.add_argument("-o", "--output", metavar="FILE",
                   help="write FILE (atomically: a temporary file in the same folder, then renamed); "
                        "default: stdout")
    e.set_defaults(func=cmd_export)

    v = sub.add_parser("validate", help="cross-check the solver against the engine routes (exit 1 on failure)",
                       description="Run the accuracy gate: for every MODEL (default: all bundled models) compare "
                                   "the solver's balancing moment and every reaction over the cycle with each "
                                   "route (the engines, and 'reference': a 40-digit mpmath re-solution that needs "
                                   "no engine), check the model's published values ([[published]] tables), and "
                                   "print route, quantity, error, tolerance and PASS/FAIL, and per model what checked it "
                                   "and what did not, and why. Routes whose engine is not installed (or that cannot "
                                   "check a model) are SKIPPED, never passed. Exit code 0: every model checked and "
                                   "every check passed; 1: a check failed or a route raised; 3: no failure, but a "
                                   "model that nothing checked (NOT CHECKED), or a route named with --engines that "
                                   "is not installed. Without --engines, the routes whose engine is not installed "
                                   "are skipped and named, and the others decide.")
    v.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files or bundled models' names (default: every bundled model, see 'kinetostat examples')")
    v.add_argument("--engines", metavar="ROUTE", nargs="+", help=f"engine routes to run (default: all): {routes}")
    v.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    v.add_argument("--junit", metavar="FILE", help="also write JUnit XML: one testcase per model x route x quantity "
                                                   "and per published value, each with its measured error")
    v.add_argument("--json", metavar="FILE", nargs="?", const="-",
                   help="also write every check as JSON (name, route, quantity, error, tolerance, unit, angle, "
                        "passed; totals; exit code) to FILE, or to stdout with '-' or no FILE (the table then "
                        "goes to stderr)")
    v.add_argument("--no-progress", action="store_true", help="no progress bar")
    v.set_defaults(func=cmd_validate)

    r = sub.add_parser("report", help="write the per-mechanism error reports (Markdown + HTML + plots)",
                       description="Write OUT/<model>/index.md and index.html (its figures linked, files beside it) per MODEL "
                                   "(default: all bundled models) with the mechanism's data, its picture, "
                                   "plots over the cycle, error tables per engine route, the seeds' published "
                                   "values where known, cycle.csv.gz, the plans at the design position and the "
                                   "interactive page; plus OUT/index.md and OUT/index.html. "
                                   "The files carry no dates or run times (printed here only); a rerun "
                                   "reproduces the numbers within their tolerances, not byte for byte (errors "
                                   "at rounding level differ in their last digits from machine to machine): "
                                   "--check DIR compares the rerun with DIR. Every file is written atomically: "
                                   "Ctrl-C (exit 130) or a full disk leaves the earlier files as they were, and "
                                   "when a model's report cannot be made the earlier index stays. Folders are "
                                   "named after the model files (ASCII letters, digits, '_', '-'; a repeated "
                                   "name gets -2, -3). Exits 0 once the reports are written, also when checks "
                                   "fail (use 'kinetostat validate' as the gate); 1 when a model's report could "
                                   "not be made or --check found a difference.")
    r.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files or bundled models' names (default: every bundled model, see 'kinetostat examples')")
    r.add_argument("--out", metavar="DIR", default="reports", help="output directory (default: ./reports)")
    r.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    r.add_argument("--engines", metavar="ROUTE", nargs="+", help=f"engine routes to run (default: all): {routes}")
    r.add_argument("--jobs", "-j", metavar="N", type=_jobs, default=None,
                   help="models reported in parallel by N worker processes (default: the number of cores; "
                        "1: in this process)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--check", metavar="DIR",
                   help="then compare OUT with the earlier reports in DIR (e.g. the committed reports/, OUT "
                        "elsewhere) and print each difference: model, file, quantity, angle or line, both "
                        "values and the tolerance (README: Reports); every number within its tolerance, every "
                        "other text equal but for the libraries' versions")
    _friction_option(r, "of the report's plans and worksheet (default first, the graphical method's; the friction "
                        "section shows both either way)")
    _law_options(r, "each model's report, analyses and plans")
    r.add_argument("--page", action=argparse.BooleanOptionalAction, default=True,
                   help="each model's interactive page, page.html, drawn anew and linked (default; --no-page: "
                        "none; docs: The interactive page)")
    r.set_defaults(func=cmd_report)

    pl = sub.add_parser("plans", help="draw the plans of the graphical method (SVG sheets, segments.csv)",
                        description="Draw MODEL's plans at one crank angle as the course texts draw them: the plan "
                                    "of positions (12 positions from the dead centre, the design position, the "
                                    "paths of the centres of mass, the assembly branches), the velocity and "
                                    "acceleration plans; one SVG sheet per plan (A3, true to scale in mm) and "
                                    "DIR/segments.csv (every drawn segment: its length in mm, the value it stands "
                                    "for, the scale). --only positions is the quick preview of a model.")
    pl.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    pl.add_argument("--at", metavar="DEG", type=_angle,
                    help="crank angle in degrees (default: the model's design position, drive.design_deg)")
    pl.add_argument("--scale", metavar="KEY=VALUE", nargs="+", type=_scale_item,
                    help="scales to use instead of the texts' rule: mu_l [m/mm], mu_v [m/(s mm)], "
                         "mu_a [m/(s^2 mm)], mu_F [N/mm], e.g. --scale mu_l=0.001 mu_v=0.2 mu_a=100 mu_F=50")
    pl.add_argument("--starting", metavar="DEG", type=_angle,
                    help="position 0 of the plan of positions (default: found, crank and rod in line)")
    pl.add_argument("--lang", choices=("en", "uk", "ru"), default=None,
                    help="language of the sheets and worksheet (default: the language of the model's text, "
                         "[lettering] language, else en)")
    pl.add_argument("--only", metavar="PLANS", type=_plan_names, action="append",
                    help="draw only these plans, comma-separated: positions, velocity, acceleration")
    pl.add_argument("--out", metavar="DIR", required=True, help="output directory (created)")
    pl.add_argument("--cycle-scales", action="store_true",
                    help="every plan at the scales of the interactive page (`kinetostat page`): chosen once for "
                         "the whole cycle (--scale is then not used)")
    _friction_option(pl, "default first (the graphical method's frictionless reactions); reactions draws each "
                         "revolute pair's friction circle with its reaction tangent to it, the guides' reactions "
                         "leaning by arctg f, the force polygons closed by them, and the worksheet's reactions with friction")
    _law_options(pl, "draw the plans")
    pl.set_defaults(func=cmd_plans)

    mo = sub.add_parser("motion", help="the machine's law of motion: J_red, M_red, omega(phi), delta, the flywheel "
                                       "(CSV, a sheet of diagrams, a summary)",
                        description="Find MODEL's steady periodic law of motion (the dynamic analysis before "
                                    "kinetostatics): the reduced moment of inertia J_red(phi), the reduced moment "
                                    "of the loads M_red(phi) and the drive's M_drive, the work and Delta T, "
                                    "omega(phi) and eps(phi) with omega_mean the drive's nominal speed, the "
                                    "coefficient of fluctuation delta and the flywheel on the crank shaft (exact, "
                                    "and by the texts' approximate methods). Writes into DIR, as one set: "
                                    "motion.csv (every array, units in the header), motion.svg and motion.pdf (one "
                                    "A3 sheet of diagrams at stated scales: the moments, the work, Delta T, J_red, "
                                    "Wittenbauer's energy-mass curve with its tangents, omega(phi)) and "
                                    "summary.txt (also printed). Without --delta or --flywheel: the model's "
                                    "[flywheel], else no flywheel.")
    mo.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    _law_options(mo, "the law of motion")
    mo.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    mo.add_argument("--lang", choices=("en", "uk", "ru"), default=None,
                    help="language of the sheet (default: the model's [lettering] language, else en)")
    mo.add_argument("--out", metavar="DIR", required=True, help="output directory (created)")
    mo.set_defaults(func=cmd_motion)

    pg = sub.add_parser("page", help="the interactive page of a mechanism: one offline HTML file, an angle slider "
                                     "over every plan", description="Write one self-contained HTML file (no network): "
                        "MODEL's plans at every degree and the design position at scales fixed for the cycle, the "
                        "values table, the force plans step by step, a check of measured lengths (docs: The interactive page).")
    pg.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    pg.add_argument("--lang", choices=("en", "uk", "ru"), default=None, help="language (default: the model's, else en)")
    pg.add_argument("--student", action="store_true", help="the student's page: data, empty tables, the grid; no answer")
    pg.add_argument("--at", metavar="DEG", type=_angle, help="angle of the check (default: the design position)")
    pg.add_argument("--out", metavar="FILE", required=True, help="the HTML file to write")
    pg.set_defaults(func=cmd_page)

    e = sub.add_parser("examples", help="list the bundled models, or copy them (with FORMAT.md) into a folder",
                       description="List the bundled models (the seeds' worked cases shipped inside the package, "
                                   "or the *.toml files of $KINETOSTAT_MODELS): name, structure formula, source. "
                                   "With --copy DIR, copy them and FORMAT.md into DIR to edit and run them.")
    e.add_argument("--copy", metavar="DIR", help="copy every bundled model and FORMAT.md into DIR (created)")
    e.add_argument("--force", action="store_true", help="with --copy: replace files already in DIR")
    e.set_defaults(func=cmd_examples)

    sc = sub.add_parser("schema", help="print the JSON Schema of the model format, for TOML editors",
                        description="Print the JSON Schema (draft-07) of the model file format. A model file that "
                                    "names it in its first line (#:schema ./model.schema.json) is completed and "
                                    "checked as it is typed by TOML editors (Even Better TOML, taplo).")
    sc.set_defaults(func=cmd_schema)

    va = sub.add_parser("variant", help="the task variants of Logvinenko, Nadtoka 2021 (tables 1.1-1.3): the model and its answer key",
                        description="Build the model of task TASK of Logvinenko, Nadtoka 2021 (1: ICE crank-slider, table 1.1; 2: "
                                    "opposed-cylinder ICE, table 1.2; 3: air compressor, table 1.3) for the three-"
                                    "digit variant CODE (the digits, written twice, select the columns of the rows "
                                    "labelled а б в г д е), run it, and write into DIR the model file "
                                    "task<T>_<CODE>.toml (its header states the columns and every assumption the "
                                    "text leaves open), its answer key at the design position phi1 (worksheet.md/"
                                    "html/csv/json and the plans' SVG sheets with segments.csv), cycle.csv and the teacher's "
                                    "pack (the student's sheet.pdf, the answer key key.pdf with the bands of a careful "
                                    "drawing, all plans true to scale on one A3 sheet plans_a3.pdf, and their HTML; where "
                                    "the plans at the text's scales do not fit it, the scales are chosen together for it "
                                    "and the key says which are coarser). "
                                    "--all writes the keys of every code (of TASK, or of all three tasks) into "
                                    "DIR/task<T>_<CODE>/ (no cycle.csv) with DIR/index.md and index.html, code -> M_bal, "
                                    "the largest reaction and the pack.")
    va.add_argument("task", metavar="TASK", nargs="?", help="task of Logvinenko, Nadtoka 2021: 1, 2 or 3 (with --all: default all)")
    va.add_argument("code", metavar="CODE", nargs="?", help="three-digit variant 000..999, e.g. 479")
    va.add_argument("--all", action="store_true", help="every code of TASK (or of every task), for a teacher")
    va.add_argument("--out", metavar="DIR", help="output directory (created; default ./task<T>_<CODE>, "
                                                 "with --all ./task_variants)")
    va.add_argument("--lang", choices=("en", "uk", "ru"), default=None,
                    help="language of the key and the index (default uk: the language of Logvinenko, Nadtoka 2021)")
    va.add_argument("--no-pack", action="store_true", help="no teacher's pack (sheet.pdf, key.pdf, plans_a3.pdf "
                                                           "and their HTML): the keys only, about 1 s faster a code")
    va.add_argument("--no-progress", action="store_true", help="no progress bar (--all)")
    va.add_argument("--page", action="store_true", help="also the variant's interactive page (page.html, linked from "
                                                        "the index; about 40 s a code)")
    va.set_defaults(func=cmd_variant)

    sw = sub.add_parser("sweep", help="analyse every combination of some parameters' values: a row of peaks per design",
                        description="Load MODEL once for every combination of the --param values (the first "
                                    "parameter the slowest), analyse it over the crank cycle and write one row per "
                                    "design: its parameters (in the model's units), peak_R_i_j (max |R(i,j)| over "
                                    "the cycle) for every pair, peak_M_bal (max |M_bal|), for a working machine "
                                    "peak_F_bal, n_singular and singular_deg (its singular crank angles), and "
                                    "error (why a design did not load or assemble; its peaks are then empty). "
                                    "The chunks of designs run in this process, or over Dask with --scheduler. "
                                    "Exit codes: 0 the table written, also when some designs failed (their rows "
                                    "keep the reason in 'error', and the summary counts them); 2 bad input; "
                                    "130 interrupted (Ctrl-C).")
    sw.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    sw.add_argument("--param", metavar="NAME=VALUES", type=_param, action="append", required=True,
                    help="a parameter of the model's [parameters] (or g) and its values: a range start:stop:step "
                         "that includes its stop (r=0.05:0.11:0.015 is 0.05, 0.065, 0.08, 0.095, 0.11), a list "
                         "(n_k=0,60,120,240,487) or one value; repeat for each parameter")
    sw.add_argument("--steps", metavar="N", type=_steps, default=360,
                    help="N equal steps over a revolution for every design (default 360)")
    sw.add_argument("--out", metavar="FILE", required=True,
                    help="the table, one row per design: FILE.parquet or FILE.csv (written atomically)")
    sw.add_argument("--full", action="store_true",
                    help="also write every angle's row of every design (the design's parameters, then the "
                         "columns of 'kinetostat analyze --out') to <stem>.angles<suffix> beside --out, e.g. "
                         "sweep.angles.parquet")
    sw.add_argument("--scheduler", metavar="WHERE",
                    help="run the chunks over Dask: 'threads' or 'processes' (this machine), or the address of a "
                         "distributed scheduler, e.g. tcp://10.0.0.5:8786 (default: in this process, no Dask)")
    sw.add_argument("--chunk", metavar="N", type=_positive("number of designs per task", "--chunk 32"), default=CHUNK,
                    help=f"designs per task (default {CHUNK})")
    _friction_option(sw, "default: the model's friction.method, else first; reactions adds to each row the cycle "
                         "efficiency eta_cycle and n_self_locking, the count of self-locking angles")
    sw.add_argument("--no-progress", action="store_true", help="no progress bar")
    sw.set_defaults(func=cmd_sweep)

    from ..tolerance import CHUNK as TOL_CHUNK, DISTRIBUTIONS, SEED_BLOCK
    tl = sub.add_parser("tolerance", help="what the parameters' tolerances do to the forces: first order and Monte Carlo",
                        description="Draw --samples designs of MODEL with each --tol parameter uniform within +-its "
                                    "limit (or normal with that sigma), analyse each over the crank cycle and compare "
                                    "with the first order from the exact derivatives. Writes into --out: "
                                    "tolerance.csv (per output's peak: nominal, first-order worst case and RSS, the "
                                    "Monte Carlo mean, std and quantiles, each parameter's share of the variance), "
                                    "tolerance.nc (every output at every angle, xarray/NetCDF; needs xarray and "
                                    "scipy) and tornado.svg. Exit codes: 0 written; 2 bad input; 130 interrupted.")
    tl.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    tl.add_argument("--tol", metavar="NAME=VALUE[UNIT]", type=_tol, action="append", required=True,
                    help="a parameter of the model's [parameters] (or g) and its limit: in the model's unit of it "
                         "(r=1e-4), in a unit of the same kind (r=0.1mm, m2=50g) or in %% of its nominal value "
                         "(m2=2%%); repeat for each parameter")
    tl.add_argument("--dist", choices=DISTRIBUTIONS, default="uniform",
                    help="uniform within +-limit (default), or normal with sigma = limit")
    tl.add_argument("--samples", metavar="N", type=_positive("number of designs", "--samples 10000"), default=10_000,
                    help="Monte Carlo designs (default 10000)")
    tl.add_argument("--seed", metavar="S", type=int, default=0, help="the draws' seed (default 0)")
    tl.add_argument("--steps", metavar="N", type=_steps, default=360,
                    help="N equal steps over a revolution for every design (default 360)")
    tl.add_argument("--out", metavar="DIR", required=True, help="folder of the outputs (made if missing; each file "
                                                                "written atomically)")
    tl.add_argument("--scheduler", metavar="WHERE",
                    help="run the chunks over Dask: 'threads' or 'processes' (this machine), or the address of a "
                         "distributed scheduler (default: in this process, no Dask)")
    tl.add_argument("--chunk", metavar="N", type=_positive("number of designs per task", "--chunk 2000"),
                    default=TOL_CHUNK, help=f"designs per task, a multiple of {SEED_BLOCK} (default {TOL_CHUNK})")
    tl.add_argument("--no-progress", action="store_true", help="no progress bar")
    tl.set_defaults(func=cmd_tolerance)
    for command in sub.choices.values():     # -q/-v also after the command: kinetostat report -q ...
        _verbosity_options(command, argparse.SUPPRESS)
    return p
