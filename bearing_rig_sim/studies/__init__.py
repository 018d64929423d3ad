"""Studies run on the dynamics engine, without ROS: steady operating points and calibration to
bench data (:mod:`.calibration`), the paper's experiments (:mod:`.experiments`) and their
reproduction with a report (:mod:`.reproduction`).
"""
