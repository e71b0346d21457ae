"""The slider-crank: the same concepts as the four-bar modules, for the second mechanism.

=======================  =====================================================================
module                   what it holds
=======================  =====================================================================
``kinematics``           positions, rates and accelerations for either assembly, vectorised;
                         the crank angles where it assembles
``massmodels``           the total centre of mass and Wunderlich's similar slider-crank
                         (his Eq. 13–19), its circle and point cases (Eq. 14, 20a–b)
``dynamics``             inverse dynamics by Newton–Euler and by equivalent mass matrices
``formulations``         forward dynamics: one equation in θ1 by virtual power, and truss
                         elements with the guide as a constraint (Meijaard & van der Wijk's
                         Sect. 5.1)
``conditions``           stationary centre of mass (Eq. 20a–b) and the classic crank
                         counterweight
=======================  =====================================================================

Conventions (the project's DESIGN.md): A0 at the origin; crank A0→A1, connecting rod A1→A2, A2
the slider's pin on the guide line ``y = e`` (the signed offset), the guide along +x; branch
``"+"`` puts the slider on the +x side of the crank pin. The slider's centre of mass is given
relative to its pin in global axes. A gas force acts between slider and frame along the guide.
"""
