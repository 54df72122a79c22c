"""rescon.models (under construction)."""
