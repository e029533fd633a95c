"""The scene quantities a fit can free, with their SI units: a plain table without dependencies,
so that the command line can name them in its help without importing numpy (``frictionlab --help``)."""

#: Scene quantities that can be freed, with their SI unit (dotted names reach into sub-models).
SCENE_QUANTITIES = {
    "u0": "m/s", "omega0": "rad/s", "mass": "kg", "radius": "m", "incline": "rad",
    "area.peak": "m^2", "area.contact_time": "s", "area.area": "m^2", "area.initial": "m^2", "area.rate": "m^2/m",
    "normal.impulse": "N*s", "normal.contact_time": "s", "normal.value": "N", "normal.coefficient": "N/m^3",
    "compliance.stiffness": "N/m", "compliance.damping": "N*s/m",
    "spring.stiffness": "1/m",  # a spring-slider's machine stiffness per unit normal force (k of rate-and-state)
}
#: The unit each freed scene quantity is shown in (reports, summaries, notebook views); others in SI.
SCENE_SHOWN = {
    "omega0": "rpm", "mass": "g", "radius": "mm", "incline": "deg", "area.peak": "mm^2", "area.contact_time": "us",
    "area.area": "mm^2", "area.initial": "mm^2", "normal.contact_time": "us", "spring.stiffness": "1/um",
}
