"""Time-domain verification: simulate an identified model on flights it was not fitted to.

See :mod:`sysid.verify.engine` for the method (Tischler's VERIFY: bias and
reference shift, RMS error and Theil inequality coefficient; chapter 3.5.3 of
the dissertation for the wind correction of Table 3.6). Each record is
simulated from all measured inputs and judged on the outputs of the axis it
excites (:func:`axis_outputs`). :mod:`sysid.verify.io` saves and reads the
result as JSON (:func:`write_verification`, :func:`read_verification`).
"""

from sysid.verify.engine import VerificationOptions, verify, verify_record
from sysid.verify.io import (
    VERIFICATION_SCHEMA,
    VERIFICATION_SCHEMA_VERSION,
    SavedVerification,
    read_verification,
    verification_from_dict,
    verification_to_dict,
    write_verification,
)
from sysid.verify.logs import Validation, verification_provenance, verify_flights, verify_identified, verify_logs
from sysid.verify.records import DoubletRecords, check_given_doublets, doublet_records
from sysid.verify.results import (
    OutputSummary,
    OutputVerification,
    RecordVerification,
    Verification,
    WindCorrection,
    mode_names,
    rms_error,
    theil_inequality,
)
from sysid.verify.submodel import axis_outputs, driven_part

__all__ = [
    "VerificationOptions",
    "verify_record",
    "verify",
    "verify_logs",
    "Validation",
    "verify_flights",
    "verify_identified",
    "verification_provenance",
    "driven_part",
    "axis_outputs",
    "doublet_records",
    "check_given_doublets",
    "DoubletRecords",
    "OutputVerification",
    "RecordVerification",
    "OutputSummary",
    "WindCorrection",
    "Verification",
    "rms_error",
    "theil_inequality",
    "mode_names",
    "VERIFICATION_SCHEMA",
    "VERIFICATION_SCHEMA_VERSION",
    "SavedVerification",
    "verification_to_dict",
    "verification_from_dict",
    "write_verification",
    "read_verification",
]
