"""Base handles and the one factory that picks base_driver's handle from its parameters.

The registry maps a handle name (base_driver's ``~base_handle``) to ``module:Class``, imported only
when that handle is created (as python-can's interface registry). ``~base_handle`` defaults to
``simple_sim`` when ``~simple_sim`` is true; with ``simple_sim`` false it names the CAN base,
``can``. A handle gets base_driver's parameters as one frozen value
(:class:`~thorvald_base.params.DriverParams`), never the raw namespace, and imports no ROS module:
one that trades messages gets them through the node's :class:`~thorvald_base.bases.handle.Ports`.

====================  =======================================================================
name                  handle
====================  =======================================================================
``simple_sim``        :class:`~thorvald_base.bases.simulated.SimulatedBase`: drives simulated in
                      the node, ramping at ``prp_sim_a`` and slewing at ``str_sim_v``
``simulated_joints``  :class:`~thorvald_base.bases.simulated_joints.SimulatedJointsBase`: drives
                      measured from a physics simulator's joints (``drive_commands`` out,
                      ``drive_states`` in; ``~measured_timeout``, 0.5 s)
``can``               :class:`~thorvald_base.bases.can_base.CanBase`: motor controllers,
                      batteries and IO boards on a python-can bus (``~can_interface_type``,
                      ``~can_interface_name``)
====================  =======================================================================
"""

import importlib
from typing import Dict, List, Type

from ..errors import ParameterError
from .handle import BaseHandle, BatteryInfo, ControllerInfo, Frame, IoInfo, MeasuredDrive

BASE_HANDLES: Dict[str, str] = {
    "simple_sim": "thorvald_base.bases.simulated:SimulatedBase",
    "simulated_joints": "thorvald_base.bases.simulated_joints:SimulatedJointsBase",
    "can": "thorvald_base.bases.can_base:CanBase",
}


def known_handles() -> List[str]:
    return sorted(BASE_HANDLES)


def handle_class_named(name: str) -> Type[BaseHandle]:
    """The class of the base handle registered as name, imported but not made; KeyError if none is."""
    module_name, _, class_name = BASE_HANDLES[name].partition(":")
    return getattr(importlib.import_module(module_name), class_name)


def handle_class(params) -> Type[BaseHandle]:
    """The class of the base handle ``params`` (base_driver's :class:`~thorvald_base.params.DriverParams`)
    asks for, imported but not made (what it supports, before a bus is opened); ParameterError for an
    unknown name."""
    name = params.handle
    if name not in BASE_HANDLES:
        origin = "" if params.base_handle else f" (simple_sim {params.simple_sim})"
        raise ParameterError(
            f"~base_handle: {name!r}{origin}: no such base handle; available: {', '.join(known_handles())}"
        )
    return handle_class_named(name)


def create_base_handle(config, params, ports=None) -> BaseHandle:
    """The base handle ``params`` (base_driver's :class:`~thorvald_base.params.DriverParams`) asks
    for, for this robot; ``ports`` is what the node offers handles that talk over topics
    (:class:`~thorvald_base.bases.handle.Ports`)."""
    return handle_class(params).from_params(config, params, ports)


__all__ = [
    "BASE_HANDLES",
    "BaseHandle",
    "BatteryInfo",
    "ControllerInfo",
    "Frame",
    "IoInfo",
    "MeasuredDrive",
    "create_base_handle",
    "handle_class",
    "handle_class_named",
    "known_handles",
]
