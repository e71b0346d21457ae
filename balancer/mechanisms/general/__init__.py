"""Any planar linkage with one degree of freedom, given by its points, bodies and sliders.

:class:`~.mechanism.LinkageMechanism` answers the mechanism interface through the general core
(:mod:`balancer.linkage`): numeric kinematics and the compiled multibody formulation.
"""
