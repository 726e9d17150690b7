#!/usr/bin/env python3
"""Flat out's per-thread CPU (docs/benchmarks.md, Flat out): runs the app in a
pty at 120x40, answers its status requests, presses x, t, d, d and prints
each thread's CPU % of one core from /proc over 5 s in each mode.
Usage: scripts/flat_out_cpu.py target/release/ballpit [flags...]"""
import os, pty, time, sys, select, subprocess
BIN=sys.argv[1]; args=sys.argv[2:]
pid, fd = pty.fork()
if pid == 0:
    os.environ['TERM']='xterm-256color'
    os.execv(BIN, [BIN]+args)
import fcntl, termios, struct
fcntl.ioctl(fd, termios.TIOCSWINSZ, struct.pack('HHHH', 40, 120, 0, 0))
buf=b''
def drain(t):
    global buf
    end=time.time()+t
    while time.time()<end:
        r,_,_=select.select([fd],[],[],0.05)
        if r:
            try: d=os.read(fd,65536)
            except OSError: return
            buf=buf[-200000:]+d
            # answer status requests
            n=d.count(b'\x1b[5n')
            if n: os.write(fd,b'\x1b[0n'*n)
def ticks():
    out={}
    for t in os.listdir(f'/proc/{pid}/task'):
        try: s=open(f'/proc/{pid}/task/{t}/stat').read()
        except: continue
        name=s[s.find('(')+1:s.rfind(')')]
        f=s[s.rfind(')')+2:].split()
        out[name]=out.get(name,0)+int(f[11])+int(f[12])
    return out
def measure(label, secs=5):
    a=ticks(); t0=time.time(); drain(secs); b=ticks(); dt=time.time()-t0
    pct={k:(b[k]-a.get(k,0))/dt for k in b}  # ticks/s at 100 Hz = %
    pool=sum(v for k,v in pct.items() if k.startswith('pool-'))
    print(f"{label}: " + " ".join(f"{k}={v:.0f}%" for k,v in sorted(pct.items()) if v>=0.5) + f"  pool-total={pool:.0f}%", flush=True)
drain(3)
measure("tick 1, off",3)
os.write(fd,b'x'); drain(3); measure("flat out, off")
os.write(fd,b't'); drain(3); measure("flat out, worker")
os.write(fd,b'd'); drain(3); measure("flat out, pool")
os.write(fd,b'd'); drain(3); measure("flat out, split")
os.write(fd,b'q'); drain(1)
