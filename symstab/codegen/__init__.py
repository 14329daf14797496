"""Code generation: the float-safe forms the kernels are generated from, the
printers and file layout (``symstab/_generated``), and any loop's kernels.
"""
