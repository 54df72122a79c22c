"""Graph robustness: bounds, exact search, MILP, generators, Sarymsakov and attack-model checks."""
