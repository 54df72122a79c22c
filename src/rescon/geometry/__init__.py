"""rescon.geometry (under construction)."""
