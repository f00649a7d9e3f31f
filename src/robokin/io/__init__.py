"""Files in and out: the edge where text becomes robots, scenes and motions.

Two kinds of module live here:

* leaf helpers that import nothing above :mod:`robokin.exceptions`, used by every
  layer that reads or writes a file: :mod:`~robokin.io.text_files` (bounded
  reading), :mod:`~robokin.io.yaml_reader` (the one YAML reader),
  :mod:`~robokin.io.atomic` (the one atomic writer), :mod:`~robokin.io.validate`
  (pydantic errors as bounded ModelErrors) and :mod:`~robokin.io.strict_json`;
* the readers and writers that build or describe a :class:`~robokin.robot.Robot`,
  a layer above ``robot.py``: :mod:`~robokin.io.robot_files` (robot files and
  their section table), :mod:`~robokin.io.actuator_section`,
  :mod:`~robokin.io.geometry_sections`, :mod:`~robokin.io.urdf_xml` (safe, strict
  XML), :mod:`~robokin.io.urdf` (URDF in), :mod:`~robokin.io.urdf_tool` (the
  links hung on the chain, the tool's tree), :mod:`~robokin.io.urdf_geometry`
  (their shapes), :mod:`~robokin.io.srdf` (SRDF in),
  :mod:`~robokin.io.urdf_export` (URDF out), :mod:`~robokin.io.dh_extract` and
  :mod:`~robokin.io.motion_files`;
* the MoveIt planning-scene readers, parts for :class:`robokin.collision.Scene`:
  :mod:`~robokin.io.moveit_scene` (``.scene`` text) and
  :mod:`~robokin.io.moveit_scene_yaml` (``moveit_msgs/PlanningScene`` YAML).

``robokin.model`` describes arms and imports nothing from here; ``robot.py``
imports from here only inside methods (``Robot.from_urdf``, ``Robot.to_urdf``).
Limits and caps: ``docs/limits-and-safety.md``.
"""
