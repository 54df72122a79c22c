"""rescon.plot (under construction)."""
