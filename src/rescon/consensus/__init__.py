"""Resilient consensus: Algorithm 1, adversaries, DoS schedules, metrics."""
