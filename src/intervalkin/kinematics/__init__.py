"""Kinematics of the 3-RPR: every formula written once, in each number system the package uses.

constants    the geometry's constants as floats, outward intervals and arb balls (one cache)
formulas     g (rho_i^2), the Jacobian A and det A: the formulas, and their float and arb versions
enclosures   certified interval enclosures of rho_i^2, A (= grad rho_i^2), det A and grad det A over boxes
point_enclosures  rho_i^2 and det A enclosed at float poses (the cheap evaluation of Krawczyk steps)
sextic       the reduction of the direct kinematics to one polynomial in t = tan(phi / 2)
reduced_equation  that reduction's coefficients as quadratics in r = rho^2 (for joint-space boxes), and the
                  aligned numerator m_2 x N, a lower bound on f near the zeros of D

Layer: imports only :mod:`intervalkin.core`; everything above evaluates kinematics through here.
"""
