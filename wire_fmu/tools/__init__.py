"""Tools above the master: what may use the physics core directly (the reeving drawing).

Like ``study/``, ``bench/`` and ``sweep/``, this layer may import everything; the
master (``master/``) reaches units only through FMI.
"""
