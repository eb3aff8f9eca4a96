"""The simulator of the paper's section 3(4): a world and a vehicle in numpy that run
RL/I programs through the Device interface (spec/simulator.md).

One file, one job: world.py loads the world file, geometry.py holds the plane geometry,
motion.py the vehicle's kinematics and odometry, tracing.py the line tracing, camera.py
the camera and image processor, occlusion.py what hides what the camera looks at,
ultrasonic.py the range sensors, simulator.py the physics clock and its faults,
device.py the Device adapter, render.py the pictures.
"""
