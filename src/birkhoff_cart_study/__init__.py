"""The study runner of birkhoff_cart: study files expanded into tasks, each task one process of the
batch engine (work_precision --measure / --reference-run, cart_simulate) run on Dask distributed,
rows appended as they finish, and tables and plots made from the rows (docs/studies.md)."""
