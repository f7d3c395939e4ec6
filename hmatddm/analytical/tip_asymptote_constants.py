"""Constants of the universal tip asymptote (Dontsov and Peirce 2015), shared by its numpy
form (:mod:`.tip_asymptote`) and its compiled inversions (:mod:`.tip_asymptote_kernels`)."""

BETA_M3 = 2.0 * 3.0**2.5          # beta_m^3 = 18 sqrt(3)
BETA_M = BETA_M3 ** (1.0 / 3.0)
BETA_C = 0.9911799823             # Dontsov and Peirce (2015): the leak-off term of delta
_C1_M = BETA_M3 / 3.0              # C_1(1/3) = 6 sqrt(3)

#: ``f`` from its series beyond this ``C`` (``tip_asymptote._f``), with ``SERIES_TERMS`` terms
SERIES_FROM = 10.0
SERIES_TERMS = 20
