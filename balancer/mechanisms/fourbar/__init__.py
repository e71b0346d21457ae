"""The four-bar linkage: everything the tool knows of it in one folder.

Its model (:mod:`.model`: lengths, links, branch) and assembly (:mod:`.assembly`: Grashof
class, assembly range), its closed-form kinematics (:mod:`.kinematics`), inverse dynamics and
shaking quantities (:mod:`.inverse`), the seeds' mass models (:mod:`.massmodels`,
:mod:`.complex_masses`) and balance conditions (:mod:`.conditions`), its four formulations of
the equations of motion (:mod:`.closed_form`, :mod:`.opened_loop`, :mod:`.lie_group`,
:mod:`.mass_matrix`) and, over them all, its :class:`~.mechanism.FourBarMechanism`.
"""
