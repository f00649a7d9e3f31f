"""Pictures of robots: matplotlib plots, the live 3D viewer, standalone HTML.

Nothing here is imported by ``import robokin``; the heavy parts load on use.
"""
