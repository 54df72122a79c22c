"""Bridge to the standalone checker in ``certificates/`` (installed as
``rescon_certificates``). rescon never checks its own answers with its own code:
this module only hands the certificate over."""

from __future__ import annotations

from typing import Any

from rescon_certificates.check import CheckResult, check

__all__ = ["CheckResult", "check_certificate"]


def check_certificate(cert: dict[str, Any]) -> CheckResult:
    """Verify a certificate with the independent checker (exact arithmetic, stdlib only).

    Returns
    -------
    CheckResult
        ``verdict`` is ``"valid"`` (every part verified; ``valid`` is True only then),
        ``"invalid"`` (``reason`` says what is malformed or refuted) or ``"unchecked"``
        (well-formed, nothing refuted, but some part was taken on trust, e.g. a
        ``milp`` proof on n > 20 nodes, or exceeds the checker's size / work / bit-size
        limits: ``unchecked`` names those parts, ``trusted`` their short names).
        ``rescon check`` exits 0, 1 and 3 for these verdicts (2: unreadable file).
    """
    return check(cert)
