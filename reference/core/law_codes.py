"""The impact laws' codes and limits as plain Python numbers (reference.core.impact_laws
uses them in compiled code; Python callers read them from here without importing numba)."""

LAW_PAPER = 0
LAW_MOREAU = 1
LAW_SEQUENTIAL = 2
LAW_COMPLIANT = 3
LAW_COMPLIANT_MASS = 4
LAW_NAMES = ("paper", "moreau", "sequential", "compliant", "compliant-mass")

# Outcomes of a law's solve
SETTLED = 0
NOT_SETTLED = 1  # sequential: MAX_SEQUENTIAL_IMPACTS reached; moreau: pivot cap
SINGULAR = 2  # a contact whose W_ii is not positive (no impulse can move it)
TOO_MANY = 3  # more than MAX_LAW_CONTACTS contacts

# the laws take at most this many contacts (Moreau's pivoting costs O(k⁴) at worst): a
# larger polygon landing flat ends the run undecidable, saying so
MAX_LAW_CONTACTS = 64
MAX_SEQUENTIAL_IMPACTS = 100_000
