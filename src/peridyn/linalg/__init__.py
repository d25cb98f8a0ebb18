"""Linear algebra of the linearised models: stiffness and mass matrices, the consistent
tangent, the matrix-free block operator, fill-reducing orderings, algebraic multigrid and the
maps between points and degrees of freedom. Asks a material for its linearisation, never for
its type."""
