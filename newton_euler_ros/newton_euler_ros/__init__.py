"""newton_euler_ros: recursive Newton-Euler inverse dynamics for ROS 2.

The numerical core lives in :mod:`newton_euler_ros.core` and imports
nothing from ROS; the ROS adapters (nodes, message conversion) sit beside
it.
"""
__version__ = '0.1.0'
