#!/usr/bin/python3
"""The contour bench's LinuxCNC driver (its DISPLAY program): switches the machine on, and
for each program in PEER_PROGRAMS (':'-separated) moves to the point its first line names,
runs it in AUTO and writes the time from its first to its last moving poll (polled every
0.2 ms; the planner itself runs on the 1 ms servo thread) to PEER_OUT, one line each."""
import os
import time

import linuxcnc

s, c = linuxcnc.stat(), linuxcnc.command()


def wait_for(pred, timeout=30.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        s.poll()
        if pred():
            return True
        time.sleep(0.001)
    return False


def idle():
    return s.interp_state == linuxcnc.INTERP_IDLE and s.queue == 0 and s.current_vel <= 1e-9


def run(prog):
    first_line = open(prog).readline()
    if first_line.startswith("(PEER_START"):
        c.mode(linuxcnc.MODE_MDI)
        c.wait_complete()
        c.mdi("G0 " + first_line[len("(PEER_START"):].strip().rstrip(")"))
        c.wait_complete(30)
        wait_for(idle)
    c.mode(linuxcnc.MODE_AUTO)
    c.wait_complete()
    c.program_open(prog)
    c.wait_complete()
    c.auto(linuxcnc.AUTO_RUN, 0)
    first = last = None
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120:
        s.poll()
        now = time.monotonic()
        if s.current_vel > 1e-9:
            first = first or now
            last = now
        if first is not None and idle():
            break
        time.sleep(0.0002)
    return (last - first) if first else -1.0


with open(os.environ["PEER_OUT"], "w") as out:
    try:
        wait_for(lambda: True)
        c.state(linuxcnc.STATE_ESTOP_RESET)
        c.wait_complete()
        c.state(linuxcnc.STATE_ON)
        c.wait_complete()
        for prog in os.environ["PEER_PROGRAMS"].split(":"):
            out.write("%s %.4f\n" % (prog, run(prog)))
            out.flush()
    except Exception as e:  # reported to the bench, which says the peer failed
        out.write("error %s\n" % e)
