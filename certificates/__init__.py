"""rescon_certificates: the standalone, trusted certificate checker (see FORMAT.md)."""

try:
    from .check import CheckResult, check, main
except ImportError:  # pragma: no cover - loaded outside its package (certificates/ on sys.path)
    from check import CheckResult, check, main  # type: ignore[no-redef]

__all__ = ["CheckResult", "check", "main"]
