"""rescon.sweep: experiment grids on Dask — reserved for issue 12 (DESIGN.md,
`rescon sweep`); nothing here yet."""
