"""rescon.optim (under construction)."""
