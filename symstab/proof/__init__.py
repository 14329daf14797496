"""Proofs: the exact identity checker and every proof obligation, and the
derivation files that ``symstab derive`` writes and checks for drift.
"""
