"""Counterweights one can make: shapes within a room, their mass properties, and CAD files.

- :mod:`.shapes`: the profiles (annulus, annular sector, rectangle) and their mass properties
  in closed form;
- :mod:`.sizing`: each family's dimensions solved for the mass, centre and inertia the
  optimiser asks, or the nearest part its room allows; a room's envelope as bounds;
- :mod:`.made`: the parts of a balancing, and the design as built from them (reported by
  :mod:`balancer.report.parts`);
- :mod:`.cad`: STEP solids and DXF profiles (the ``cad`` extra: build123d, ezdxf).
"""
