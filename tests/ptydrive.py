"""ptydrive.py -- run a program on a pseudo-terminal as a person at a keyboard would:
wait until it has asked (its output goes quiet), type the next key sequence, and
collect the screen.  Shared by every terminal test (tty_session.py, t_65, t_66)."""
import os, pty, select, time

def _read(fd, quiet):
    """What the program prints within `quiet` seconds: b"" if it is quiet, None at
    end of output."""
    r, _, _ = select.select([fd], [], [], quiet)
    if not r:
        return b""
    try:
        return os.read(fd, 65536) or None
    except OSError:
        return None

def drive(argv, keys, cwd=None, home=None, timeout=60, quiet=0.3):
    """Run argv in cwd with HOME=home and TERM=dumb, typing each of keys (bytes) in
    turn once the program has gone quiet.  Returns (exit status, screen text)."""
    pid, fd = pty.fork()
    if pid == 0:
        if cwd:
            os.chdir(cwd)
        if home:
            os.environ["HOME"] = home
        os.environ["TERM"] = "dumb"
        os.execv(argv[0], argv)
    out, deadline, status = b"", time.time() + timeout, None
    for k in keys:
        while time.time() < deadline:
            data = _read(fd, quiet)
            if not data:
                break
            out += data
        os.write(fd, k)
    while time.time() < deadline:
        data = _read(fd, quiet)
        if data is None:
            break
        out += data
        if not data:
            wpid, st = os.waitpid(pid, os.WNOHANG)
            if wpid:
                status = st
                break
    if status is None:
        _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status), out.decode(errors="replace")
