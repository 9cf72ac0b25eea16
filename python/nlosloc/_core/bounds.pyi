"""
Performance bounds: GCRB (Huerta appendix).
"""
from __future__ import annotations
import numpy
import numpy.typing
import typing
__all__: list[str] = ['GcrbResult', 'gcrb_rtoa']
class GcrbResult:
    """
    Information matrices and position bounds of gcrb_rtoa.
    """
    def __repr__(self) -> str:
        ...
    @property
    def J(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (D+1, D+1) J = J_D + J_P, eq. (46).
        """
    @property
    def J_data(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        J_D = H Q^-1 H^T, eq. (43).
        """
    @property
    def position_crb(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (D, D) [J_D^-1]_p, no prior.
        """
    @property
    def position_gcrb(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (D, D) [J^-1]_p, eqs. (47)-(48).
        """
def gcrb_rtoa(anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], Q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], sigma_tau2: typing.SupportsFloat | typing.SupportsIndex) -> GcrbResult:
    """
    GCRB of the position from RTOA with a clock prior of variance sigma_tau2 (inf: no prior). anchors (B, D), position (D,), Q (B, B) measurement covariance: positive definite and symmetric (max |Q - Q^T| <= 1e-10 ||Q||_F; ValueError naming Q otherwise).
    """
