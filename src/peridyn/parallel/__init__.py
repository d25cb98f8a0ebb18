"""MPI domain decomposition: the communicator (``comm``), the partition of the points by
recursive coordinate bisection (``partition``), ghost points and their exchange (``halo``), a
rank's part of the body with the collectives a run needs (``domain``) and the observers that
run on rank 0 (``observers``). The numba kernels run unchanged on each rank's local arrays.
"""
