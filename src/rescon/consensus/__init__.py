"""rescon.consensus (under construction)."""
