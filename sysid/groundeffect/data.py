"""Thrust-ratio data, F/F0 against Z/R, from a test rig or from the hover steps of a flight log."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from flightlogs.errors import DataError
from flightlogs.readers.dispatch import ReadOptions
from sysid.groundeffect.flight import flight_thrust_ratio
from sysid.groundeffect.records import GroundEffectDataConfig, HoverStep, HoverSteps, ThrustRatioData

__all__ = [
    "HoverStep",
    "HoverSteps",
    "ThrustRatioData",
    "GroundEffectDataConfig",
    "rig_thrust_ratio",
    "load_thrust_ratio",
]

_PLAUSIBLE_MEDIAN = (0.5, 2.0)  # median F/F0 of rig readings: ground effect moves thrust by tens of percent at most
_LOG_SUFFIXES = (".ulg", ".bin", ".tlog")


def rig_thrust_ratio(
    height_m: np.ndarray,
    thrust_n: np.ndarray,
    *,
    rotor_radius_m: float,
    f0_n: float | None = None,
    reference_height_ratio: float = 8.0,
    source: str = "",
) -> ThrustRatioData:
    """F/F0 against Z/R from rig readings of thrust at known heights.

    Parameters
    ----------
    height_m : ndarray, shape (n_rows,)
        Rotor plane above the surface, m.
    thrust_n : ndarray, shape (n_rows,)
        Measured thrust, N.
    rotor_radius_m : float
        Propeller radius R, m.
    f0_n : float, optional
        Thrust out of ground effect, N. Default: the mean thrust of the rows
        with Z/R > `reference_height_ratio` (those rows stay in the data).
    reference_height_ratio : float, optional
        Z/R above which the rows give F0.
    source : str, optional
        Name of the data for messages.

    Returns
    -------
    ThrustRatioData

    Raises
    ------
    DataError
        If F0 is not given and no row lies above `reference_height_ratio`, or
        if the median F/F0 of the readings lies outside 0.5-2 (F0 or the
        thrust unit is wrong: ground effect changes thrust by tens of percent).

    Notes
    -----
    An F0 taken from rows at Z/R > 8 carries what ground effect remains
    there: 0.3 % for eq. 2.4 at Z/R = 8, none for eq. 2.5.

    Examples
    --------
    >>> data = rig_thrust_ratio(np.array([0.05, 0.2, 0.25]), np.array([0.42, 0.40, 0.40]), rotor_radius_m=0.0225)
    >>> data.height_ratio.round(2).tolist(), data.thrust_ratio.round(4).tolist(), data.f0_source
    ([2.22, 8.89, 11.11], [1.05, 1.0, 1.0], 'mean of 2 rows with Z/R > 8')
    """
    x = np.asarray(height_m, dtype=np.float64) / rotor_radius_m
    thrust = np.asarray(thrust_n, dtype=np.float64)
    if f0_n is None:
        reference = x > reference_height_ratio
        if not np.any(reference):
            raise DataError(
                f"{source or 'rig data'}: no reading above Z/R = {reference_height_ratio:g} "
                f"(height {reference_height_ratio * rotor_radius_m:.3f} m) to give F0; "
                "give F0 (--f0) or add readings out of ground effect"
            )
        f0 = float(np.mean(thrust[reference]))
        how = f"mean of {int(reference.sum())} row{'s' if reference.sum() > 1 else ''} with Z/R > {reference_height_ratio:g}"
    else:
        f0, how = float(f0_n), "given"
    ratio = thrust / f0
    median = float(np.median(ratio)) if ratio.size else 1.0
    if not _PLAUSIBLE_MEDIAN[0] <= median <= _PLAUSIBLE_MEDIAN[1]:
        raise DataError(
            f"{source or 'rig data'}: with F0 = {f0:.4g} N ({how}) the median F/F0 of the readings is "
            f"{median:.3g}, far from 1 out of ground effect; check F0 (--f0) and the thrust unit "
            f"(median thrust {float(np.median(thrust)):.4g} N)"
        )
    return ThrustRatioData(
        height_ratio=x, thrust_ratio=ratio, rotor_radius_m=rotor_radius_m, source=source, f0_source=how, f0_n=f0
    )


def load_thrust_ratio(
    path: str | Path,
    config: GroundEffectDataConfig,
    *,
    progress: Callable[[int, int], None] | None = None,
    reading: ReadOptions = ReadOptions(),
) -> ThrustRatioData:
    """F/F0 against Z/R from a rig CSV or a flight log, told apart by content.

    A file that reads as a PX4 ULog, ArduPilot DataFlash or MAVLink
    telemetry log is a flight log (:func:`sysid.groundeffect.flight.flight_thrust_ratio`);
    any other text file is a rig CSV (:func:`flightlogs.readers.rig.read_rig_csv`), unless
    it is named ``.ulg``, ``.bin`` or ``.tlog``: then the log reader's error stands. With a
    column map (``reading.table_map``), a CSV or Parquet table is a flight (motion capture: height, motor commands or
    speeds) read through it.

    Parameters
    ----------
    path : str or Path
        The file.
    config : GroundEffectDataConfig
        Rotor radius, F0 or k_f and mass, columns.
    progress : callable, optional
        ``progress(done, total)`` in bytes while a flight log is read.
    reading : ReadOptions, optional
        The column map of a flight table (``height_agl``, ``motor_1..n``), and whether a log of
        another vehicle is refused.

    Returns
    -------
    ThrustRatioData

    Raises
    ------
    DataError, LogFormatError, MissingSignalError
        If the file cannot be read or holds no usable points.
    """
    from flightlogs.errors import LogFormatError
    from flightlogs.readers.detect import detect_format

    path = Path(path)
    try:
        detect_format(path)
    except LogFormatError:
        if reading.table_map is None and _is_text(path) and path.suffix.lower() not in _LOG_SUFFIXES:
            return _rig(path, config)
        if reading.table_map is None:
            raise
    from flightlogs.readers.dispatch import read_log

    return flight_thrust_ratio(read_log(path, progress=progress, reading=reading), config)


def _is_text(path: Path) -> bool:
    try:
        with path.open("rb") as stream:
            head = stream.read(4096)
    except OSError:
        return False
    return bool(head.strip()) and b"\x00" not in head


def _rig(path: Path, config: GroundEffectDataConfig) -> ThrustRatioData:
    from flightlogs.readers.rig import read_rig_csv

    rig = read_rig_csv(
        path,
        height_column=config.height_column,
        thrust_column=config.thrust_column,
        height_unit=config.height_unit,
        thrust_unit=config.thrust_unit,
    )
    return rig_thrust_ratio(
        rig.height_m,
        rig.thrust_n,
        rotor_radius_m=config.rotor_radius_m,
        f0_n=config.f0_n,
        reference_height_ratio=config.reference_height_ratio,
        source=path.name,
    )
