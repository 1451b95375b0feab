"""Contact, friction and oil-film laws of clearance joints (each formula once; Numba functions where the kernel calls them)."""
