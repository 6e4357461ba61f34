# colcon environment hook (colcon.pkg): the install prefix on AMENT_PREFIX_PATH, where ROS 2's
# ament index looks for packages (ros2 run, ros2 pkg, ros2 interface).
_colcon_prepend_unique_value AMENT_PREFIX_PATH "$COLCON_CURRENT_PREFIX"
