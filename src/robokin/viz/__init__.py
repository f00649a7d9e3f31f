"""Pictures of robots: matplotlib plots, the live 3D viewer, standalone HTML.

Nothing here is imported by ``import robokin``; the heavy parts (matplotlib, viser)
load on use. ``robokin.viz.plot_robot(robot, q)`` draws an arm (the Robot itself
does not draw: the core imports nothing from here).
"""

from robokin.viz.plots import plot_robot

__all__ = ["plot_robot"]
