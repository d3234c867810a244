"""core/: the ground floor, imported by every layer above.

geometry   the manipulator as exact, validated data (the paper's is the default)
exact      exact numbers to float bounds (standard library only)
interval   outward-rounded interval arithmetic over numpy: the rounding layer
rows       distinct rows of arrays, bit for bit, by hashing (evaluate shared work once)
ball       midpoint-radius arithmetic with a priori rounding bounds, for batched dot products
status     Status and Count: how much of an answer is proved
errors     one base error and one subclass per kind
files      the one atomic file writer
version    the package version
"""
