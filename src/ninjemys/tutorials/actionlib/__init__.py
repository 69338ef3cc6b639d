"""The actionlib_tutorials programs: ``rosrun actionlib_tutorials fibonacci_server`` and friends.

Written against ROS 1's Python API (rospy + actionlib), as the tutorials on the ROS wiki are:
``fibonacci_server``/``fibonacci_client`` (Fibonacci action, one step a second), ``averaging_server``/
``averaging_client`` (statistics of ``/random_number`` over a number of samples) and ``gen_numbers.py``
(the number source the averaging tutorial runs: normally distributed around 5 at 20 Hz).
"""
