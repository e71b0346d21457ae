"""CasADi's symbols for the linkage equations.

The equations of :mod:`balancer.linkage` are written against
:class:`~balancer.linkage.vectors.Ops`; :class:`CasadiOps` evaluates them on CasADi's SX
symbols, for the compiled formulations (:mod:`balancer.formulations`) and the straight-line
programs of :mod:`.program`.
"""

from __future__ import annotations

from .vectors import Factor, Num, Ops


class CasadiOps(Ops):
    """The elementary functions of :class:`balancer.linkage.vectors.Ops` for CasADi symbols.

    CasADi is imported by each function (once loaded, a dictionary lookup): importing this
    module does not load it.
    """

    @staticmethod
    def sqrt(x: Num) -> Num:
        import casadi as ca

        return ca.sqrt(x)

    @staticmethod
    def sin(x: Num) -> Num:
        import casadi as ca

        return ca.sin(x)

    @staticmethod
    def cos(x: Num) -> Num:
        import casadi as ca

        return ca.cos(x)

    @staticmethod
    def atan2(y: Num, x: Num) -> Num:
        import casadi as ca

        return ca.atan2(y, x)

    @staticmethod
    def where(condition: Num, a: Num, b: Num) -> Num:
        import casadi as ca

        return ca.if_else(condition, a, b)

    @staticmethod
    def factor(a: list[list[Num]]) -> Factor:
        """``A`` factored for its solves; a dense remainder by CasADi's symbolic QR."""
        return Factor(a, dense=_dense_solve)


def _dense_solve(block: list[list[Num]], columns: list[list[Num]]) -> list[list[Num]]:
    """``X`` with ``A·X = B`` for symbols: ``A`` k×k and ``B`` k×m as lists of rows."""
    import casadi as ca

    a = ca.vertcat(*[ca.horzcat(*row) for row in block])
    b = ca.vertcat(*[ca.horzcat(*row) for row in columns])
    x = ca.solve(a, b)
    return [[x[i, j] for j in range(b.size2())] for i in range(b.size1())]


__all__ = ["CasadiOps"]
