"""ROS 1 bag v2.0 files: the format as a library (reader, writer, reindex) and the record/play nodes."""
