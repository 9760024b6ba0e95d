"""The machine around the helix in operation (issue 43), as numpy laws: the rotor's
table (:mod:`.rotor`), the generator's torque (:mod:`.generator`), the wind's profile
(:mod:`.wind`) and the rigid shaft's operating points (:mod:`.rigid_shaft`).

No FE code: parameters/, solvers/, studies/ and references/ import it alike.  Each
law is built from a scene by its module's ``from_params(params)`` (None when the scene
has it off); the laws take SI values (rad/s, m/s, kg/m^3) and give SI values.
"""
