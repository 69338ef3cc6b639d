"""Package directories (package.xml only) for the ROS packages whose executables ninjemys ships."""
