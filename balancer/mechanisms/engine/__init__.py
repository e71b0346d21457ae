"""The piston engine: cylinders on one crankshaft, rods, pistons, balance shafts, gas.

Its model (:mod:`.model`: cylinders, crankshaft, shafts, the gas cycle and firing order) and,
over it, its :class:`~.mechanism.EngineMechanism`: a general linkage of slider-cranks on one
crankshaft (exact kinematics, the general core's inverse dynamics and rocking couple) with the
crankshaft's masses and the balance shafts as rotors.
"""
