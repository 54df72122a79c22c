"""rescon.sweep (under construction)."""
