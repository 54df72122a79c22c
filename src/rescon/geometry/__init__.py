"""rescon.geometry: exact safe kernels Ψ(X, F), their points, emptiness certificates and
Tverberg partitions (public entry points are re-exported by :mod:`rescon`)."""
