"""Physical simulators and exact error models: what the sensors measure and why.

- :mod:`navlib.sensors.compass` -- three-axis magnetometer compass on a level turntable (papers A, B);
- :mod:`navlib.sensors.planar` -- the exact five-parameter heading-error model of a level compass;
- :mod:`navlib.sensors.ins` -- static-base error propagation of a single-axis rotation INS and paper C's
  Table 1 closed forms;
- :mod:`navlib.sensors.trajectory` -- level flight and yaw S-manoeuvres with consistent ideal IMU increments (E);
- :mod:`navlib.sensors.strapdown` -- strapdown INS with IMU errors and a star sensor (E);
- :mod:`navlib.sensors.ins15` -- the 15-state ENU phi-angle error model (+ gyro scale-factor states) (E);
- :mod:`navlib.sensors.accelerometer` -- IEEE Std 1293 tumble test of a quartz-flexure accelerometer in a
  temperature chamber (paper D).
"""
