"""Units every layer shares: accelerations are in standard g (9.80665 m/s², CGPM 1901), so a site whose
gravity differs reads |g| ≠ 1 at rest."""

STANDARD_GRAVITY_M_S2 = 9.80665


def site_gravity_g(gravity_m_s2: float) -> float:
    """The site's gravity in standard g: what a perfect accelerometer at rest there reads."""
    return gravity_m_s2 / STANDARD_GRAVITY_M_S2


def gravity_statement(gravity_m_s2: float) -> str:
    """The gravity every output is relative to, and a warning when it is only the standard value."""
    if gravity_m_s2 == STANDARD_GRAVITY_M_S2:
        return (f"{gravity_m_s2} m/s², the standard value, not the site's: state gravity_m_s2 in the rig config "
                "(outputs are in standard g only where the site's gravity is the standard one)")
    return f"{gravity_m_s2:.6g} m/s² at the site (outputs in standard g, {STANDARD_GRAVITY_M_S2} m/s²)"
