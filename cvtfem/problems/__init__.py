"""Standard ODE test problems (spec §12): each function returns a :class:`Problem`."""
from cvtfem.problems.base import Problem
from cvtfem.problems.classic import (coupled_oscillators, limit_cycle, oscillator,
                                     prothero_robinson, van_der_pol, van_der_pol_stiff)
from cvtfem.problems.heat import heat1d
from cvtfem.problems.mechanics import bouncing_ball, bouncing_ball_impacts, sliding_point
from cvtfem.problems.testset import hires, pleiades, robertson

__all__ = ["Problem", "oscillator", "limit_cycle", "van_der_pol", "prothero_robinson",
           "coupled_oscillators", "heat1d", "bouncing_ball", "bouncing_ball_impacts",
           "sliding_point", "hires", "pleiades", "robertson", "van_der_pol_stiff", "PROBLEMS"]

#: Name -> factory, for the CLI and studies.
PROBLEMS = {"oscillator": oscillator, "limit_cycle": limit_cycle, "van_der_pol": van_der_pol,
            "prothero_robinson": prothero_robinson, "coupled_oscillators": coupled_oscillators,
            "heat1d": heat1d, "bouncing_ball": bouncing_ball, "sliding_point": sliding_point,
            "hires": hires, "pleiades": pleiades, "robertson": robertson,
            "van_der_pol_stiff": van_der_pol_stiff}
