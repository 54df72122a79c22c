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
        ``valid``, ``reason`` and ``trusted`` (proof methods accepted without
        re-verification, e.g. ``milp``).
    """
    return check(cert)
