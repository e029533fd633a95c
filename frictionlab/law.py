"""Deprecated location of the law API, kept so that plugins written against ``frictionlab.law`` keep
working. Import from ``frictionlab`` (``from frictionlab import FrictionLaw, ParamSpec``) or from
``frictionlab.physics.law``; every name here is looked up there."""
from .physics import law as _law


def __getattr__(name: str):
    return getattr(_law, name)
