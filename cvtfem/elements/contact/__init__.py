"""Pin–sheave contact primitives (contact-models digest): regularised friction, impact at onset,
Hertz contact at the pin-axis point (H1) and with refined biconvex kinematics (H2), event
indicators. Element-level, vectorised over contacts; the chain families assemble them.
"""
