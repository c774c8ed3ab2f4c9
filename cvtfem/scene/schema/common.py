"""Scene keys shared by every kind of machine: identity, solver, output."""
from __future__ import annotations

from cvtfem.methods_registry import MethodNames
from cvtfem.scene.schema.base import REQUIRED, Key, Table, TableArray

#: Method names understood by ``cvtfem.integrate.solve`` (its own and scipy's): a live view of
#: :mod:`cvtfem.methods_registry`, so a method registered at run time is a valid ``solver.method``.
METHODS = MethodNames()

EVENT = TableArray("event", "Events of a run: a named scalar output crossing a value (located on the step's "
                   "dense output; recorded in the results file).", Table("event", "One event.", (
    Key("output", "str", "Scalar output whose crossing is the event (e.g. 'ratio'; see `cvtfem describe`).", "",
        REQUIRED),
    Key("value", "float", "Value the output crosses, in the output's unit.", "as output", REQUIRED),
    Key("direction", "str", "Crossings that count: the output rising through `value`, falling, or either.", "",
        "either", choices=("rising", "falling", "either")),
    Key("terminal", "bool", "End the run at the event (else it is recorded and the run goes on).", "", True),
    Key("name", "str", "Name of the event in the results file (empty: '<output> = <value>').", "", ""),
)))

SOLVER = Table("solver", "Time integration settings (used by `cvtfem run`).", (
    Key("method", "str", "Integration method.", "", "Radau", choices=METHODS),
    Key("options", "str[]", "Options of `solver.method` as key=value, e.g. ['scheme=imex-rk4', 'friction=all'] for "
        "'strang-friction' (an option the method does not take is refused with the list it takes; scipy's methods "
        "take none).", "", ()),
    Key("t_end", "float", "Simulated time to reach.", "s", 1.0, gt=0.0),
    Key("h", "float", "Fixed step, or initial step of adaptive methods (0: automatic).", "s", 0.0, ge=0.0),
    Key("rtol", "float", "Relative tolerance of adaptive methods.", "-", 1e-6, gt=0.0, lt=1.0),
    Key("atol", "float", "Absolute tolerance of adaptive methods.", "-", 1e-9, gt=0.0),
    Key("max_steps", "int", "Step budget; the run fails with a clear message past it.", "-", 10_000_000, ge=1),
    Key("error_check", "int", "Fixed steps: estimate the local error every this many steps and warn when it exceeds "
        "rtol/atol (0: off).", "-", 20, ge=0),
    Key("on_failure", "str", "On a numerical failure: 'stop' (keep the partial results, exit 3) or 'retry' (from the "
        "last checkpoint with half the step, then with `solver.fallback`).", "", "stop", choices=("stop", "retry")),
    Key("max_retries", "int", "Retries of `on_failure = 'retry'` before the run fails.", "-", 3, ge=1),
    Key("fallback", "str", "Method of the last retry (robust, implicit).", "", "Radau", choices=METHODS),
    EVENT,
))

OUTPUT = Table("output", "What a run writes and how often.", (
    Key("step", "float", "Output sampling interval of time histories.", "s", 1e-3, gt=0.0),
    Key("names", "str[]", "Outputs to record (empty: all the model offers; see `cvtfem describe`).", "", ()),
    Key("flush_interval", "float", "Wall time between flushes of the results file.", "s", 2.0, gt=0.0),
    Key("checkpoint_interval", "float", "Simulated time between full-state checkpoints (0: none).", "s", 0.0, ge=0.0),
    Key("state", "bool", "Also record the full state vector x as the series `state` (to linearise the model at "
        "stored times: `cvtfem campbell-run`, `cvtfem jacobian-spectrum`).", "", False),
))

IDENTITY = (
    Key("title", "str", "Short name of the scene.", "", ""),
    Key("description", "str", "One-line description (shown by `cvtfem scenes` for presets).", "", ""),
    Key("preset", "str", "Built-in preset this scene starts from (its keys can be overridden).", "", ""),
    Key("seed", "int", "Seed of every random choice (e.g. the long/short link pattern).", "-", 0, ge=0),
)
