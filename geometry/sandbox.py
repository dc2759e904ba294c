"""A seccomp-BPF filter that keeps a process from running programs and from changing files.

:func:`confine` installs it in the calling process (all its threads), for good: from then
on starting a program (``execve``, ``execveat``, ``fork``, ``vfork``, ``clone`` without
``CLONE_THREAD``), opening a file for writing, creating, deleting, renaming, linking or
truncating a file or folder, changing modes, owners, times or extended attributes,
changing the working folder, opening a socket, signalling another process, injecting
terminal input (``TIOCSTI``), tracing, mounting, ``io_uring`` and the other escapes listed
in :data:`DENIED` fail with ``EPERM``. ``clone3`` fails with ``ENOSYS`` (glibc then falls
back to ``clone``, whose flags the filter can read); ``openat2`` too (its flags are behind a
pointer). Reading files, threads, memory and already-open pipes stay allowed.

Where the kernel offers user notification (Linux 5.0+), the denials go through a listener
instead, which a supervising process (the parent) holds and answers (:func:`answer`: ``EPERM``),
so that every attempt is known, not only failed. Linux on
x86_64 and aarch64 only (:func:`available`); elsewhere :func:`confine` raises ``OSError``.
"""
from __future__ import annotations

import ctypes
import errno
import os
import platform
import struct
import threading

_ARCH = {"x86_64": 0xC000003E, "aarch64": 0xC00000B7}
"""AUDIT_ARCH_* of the supported machines."""
_COMMON = {  # asm-generic numbers, shared by x86_64 from 424 on
    "pidfd_send_signal": 424, "io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427,
    "open_tree": 428, "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432, "fspick": 433,
    "pidfd_open": 434, "clone3": 435, "openat2": 437, "mount_setattr": 442, "fchmodat2": 452}
_NR = {
    "x86_64": {"ioctl": 16, "socket": 41, "socketpair": 53, "clone": 56, "fork": 57, "vfork": 58, "execve": 59,
               "kill": 62, "truncate": 76, "chdir": 80, "fchdir": 81, "rename": 82, "mkdir": 83, "rmdir": 84,
               "creat": 85, "link": 86, "unlink": 87, "symlink": 88, "chmod": 90, "fchmod": 91, "chown": 92,
               "fchown": 93, "lchown": 94, "ptrace": 101, "rt_sigqueueinfo": 129, "utime": 132, "mknod": 133,
               "uselib": 134, "pivot_root": 155, "chroot": 161, "acct": 163, "mount": 165, "umount2": 166,
               "swapon": 167, "swapoff": 168, "reboot": 169, "init_module": 175, "delete_module": 176,
               "quotactl": 179, "setxattr": 188, "lsetxattr": 189, "fsetxattr": 190, "removexattr": 197,
               "lremovexattr": 198, "fremovexattr": 199, "tkill": 200, "tgkill": 234, "utimes": 235,
               "mq_open": 240, "kexec_load": 246, "add_key": 248, "request_key": 249, "keyctl": 250,
               "open": 2, "openat": 257, "mkdirat": 258, "mknodat": 259, "fchownat": 260, "futimesat": 261,
               "unlinkat": 263, "renameat": 264, "linkat": 265, "symlinkat": 266, "fchmodat": 268,
               "unshare": 272, "utimensat": 280, "rt_tgsigqueueinfo": 297, "perf_event_open": 298,
               "fanotify_init": 300, "name_to_handle_at": 303, "open_by_handle_at": 304, "setns": 308,
               "process_vm_readv": 310, "process_vm_writev": 311, "finit_module": 313, "renameat2": 316,
               "seccomp": 317, "bpf": 321, "execveat": 322, "userfaultfd": 323, **_COMMON},
    "aarch64": {"setxattr": 5, "lsetxattr": 6, "fsetxattr": 7, "removexattr": 14, "lremovexattr": 15,
                "fremovexattr": 16, "ioctl": 29, "mknodat": 33, "mkdirat": 34, "unlinkat": 35, "symlinkat": 36,
                "linkat": 37, "renameat": 38, "umount2": 39, "mount": 40, "pivot_root": 41, "truncate": 45,
                "chdir": 49, "fchdir": 50, "chroot": 51, "fchmod": 52, "fchmodat": 53, "fchownat": 54,
                "fchown": 55, "openat": 56, "quotactl": 60, "utimensat": 88, "acct": 89, "unshare": 97,
                "kexec_load": 104, "init_module": 105, "delete_module": 106, "ptrace": 117, "kill": 129,
                "tkill": 130, "tgkill": 131, "rt_sigqueueinfo": 138, "reboot": 142, "mq_open": 180,
                "socket": 198, "socketpair": 199, "add_key": 217, "request_key": 218, "keyctl": 219,
                "clone": 220, "execve": 221, "swapon": 224, "swapoff": 225, "rt_tgsigqueueinfo": 240,
                "perf_event_open": 241, "fanotify_init": 262, "name_to_handle_at": 264, "open_by_handle_at": 265,
                "setns": 268, "process_vm_readv": 270, "process_vm_writev": 271, "finit_module": 273,
                "renameat2": 276, "seccomp": 277, "bpf": 280, "execveat": 281, "userfaultfd": 282, **_COMMON},
}
_ALLOWED = {"ioctl", "open", "openat", "clone", "kill", "tgkill", "rt_sigqueueinfo", "rt_tgsigqueueinfo", "seccomp",
            "clone3", "openat2"}
DENIED = tuple(sorted(set(_NR["x86_64"]) - _ALLOWED))
"""System calls refused outright (those of the machine that exist there)."""
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND
"""open/openat flags refused (O_TMPFILE needs O_WRONLY or O_RDWR)."""
_CLONE_THREAD = 0x10000
_IOCTL_DENIED = (0x5412, 0x541C)
"""TIOCSTI (push input into a terminal) and TIOCLINUX."""

_RET_KILL, _RET_ERRNO, _RET_NOTIFY, _RET_ALLOW = 0x80000000, 0x00050000, 0x7FC00000, 0x7FFF0000
_LD, _JEQ, _JGE, _JSET, _RET = 0x20, 0x15, 0x35, 0x45, 0x06
_PR_SET_NO_NEW_PRIVS, _PR_SET_SECCOMP, _SECCOMP_MODE_FILTER = 38, 22, 2
_SECCOMP_SET_MODE_FILTER, _FLAG_TSYNC, _FLAG_NEW_LISTENER, _FLAG_TSYNC_ESRCH = 1, 1, 8, 16
_NOTIF_RECV, _NOTIF_SEND = 0xC0502100, 0xC0182101
"""SECCOMP_IOCTL_NOTIF_RECV/SEND (struct seccomp_notif: 80 bytes, seccomp_notif_resp: 24)."""


def machine() -> str | None:
    """The supported machine this is (``x86_64``/``aarch64``), or None."""
    m = platform.machine().lower()
    m = {"amd64": "x86_64", "arm64": "aarch64"}.get(m, m)
    return m if platform.system() == "Linux" and m in _NR else None


def available() -> bool:
    """Whether :func:`confine` can work here (Linux on x86_64 or aarch64)."""
    return machine() is not None


def _program(arch: str, deny: int, pid: int) -> bytes:
    """The BPF program: a list of (code, jt, jf, k) with symbolic jump targets resolved."""
    nr = _NR[arch]
    lo = lambda i: 16 + 8 * i  # noqa: E731  (low word of argument i, little endian)
    prog: list[tuple] = [(_LD, 0, 0, 4), (_JEQ, 1, 0, _ARCH[arch]), (_RET, 0, 0, _RET_KILL), (_LD, 0, 0, 0)]
    if arch == "x86_64":
        prog.append((_JGE, "deny", 0, 0x40000000))  # the x32 ABI
    for name in DENIED:
        if name in nr:
            prog.append((_JEQ, "deny", 0, nr[name]))
    for name in ("clone3", "openat2"):
        prog.append((_JEQ, "nosys", 0, nr[name]))
    checks = [("clone", 0, _JSET, _CLONE_THREAD, "allow", "deny"), ("openat", 2, _JSET, _WRITE_FLAGS, "deny", "allow"),
              ("kill", 0, _JEQ, pid, "allow", "deny"), ("tgkill", 0, _JEQ, pid, "allow", "deny"),
              ("rt_sigqueueinfo", 0, _JEQ, pid, "allow", "deny"), ("rt_tgsigqueueinfo", 0, _JEQ, pid, "allow", "deny")]
    if arch == "x86_64":
        checks.append(("open", 1, _JSET, _WRITE_FLAGS, "deny", "allow"))
    for name, arg, op, k, yes, no in checks:
        prog += [(_JEQ, 0, 2, nr[name]), (_LD, 0, 0, lo(arg)), (op, yes, no, k)]
    prog += [(_JEQ, 0, 1 + len(_IOCTL_DENIED), nr["ioctl"]), (_LD, 0, 0, lo(1))]
    prog += [(_JEQ, "deny", 0, k) for k in _IOCTL_DENIED]
    labels = {"allow": len(prog), "deny": len(prog) + 1, "nosys": len(prog) + 2}
    prog += [(_RET, 0, 0, _RET_ALLOW), (_RET, 0, 0, deny), (_RET, 0, 0, _RET_ERRNO | errno.ENOSYS)]
    out = []
    for i, (code, jt, jf, k) in enumerate(prog):
        jt, jf = (labels[j] - i - 1 if isinstance(j, str) else j for j in (jt, jf))
        assert 0 <= jt < 256 and 0 <= jf < 256
        out.append(struct.pack("=HBBI", code, jt, jf, k & 0xFFFFFFFF))
    return b"".join(out)


def _libc():
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    libc.prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong]
    libc.ioctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p]
    return libc


def threads() -> int:
    """Threads of this process (those of Python where /proc is missing)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("Threads:"))
    except OSError:
        return threading.active_count()


def confine(listen: bool = True) -> int | None:
    """Install the filter in this process (irreversibly). With ``listen``, denials go to a
    seccomp listener where the kernel has them: its file descriptor is returned, for a
    supervising process to :func:`answer` (the denied call waits until then). Otherwise
    (or without listener support) denials fail at once with EPERM and None is returned.
    The filter covers every thread of the process. Raises ``OSError`` if it cannot be
    installed (another machine, a kernel without seccomp)."""
    arch = machine()
    if arch is None:
        raise OSError(errno.ENOSYS, f"seccomp filters are supported on Linux x86_64/aarch64, not {platform.machine()}")
    libc = _libc()
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
    tries = [(_RET_NOTIFY, _FLAG_NEW_LISTENER | _FLAG_TSYNC | _FLAG_TSYNC_ESRCH)] if listen else []
    tries.append((_RET_ERRNO | errno.EPERM, _FLAG_TSYNC))  # every thread of the process (Linux 3.17+)
    for deny, flags in tries:
        prog = _fprog(arch, deny)
        fd = libc.syscall(_NR[arch]["seccomp"], _SECCOMP_SET_MODE_FILTER, flags, prog)
        if fd >= 0:
            return int(fd) if flags & _FLAG_NEW_LISTENER else None
    if threads() == 1 and libc.prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, ctypes.addressof(prog), 0, 0) == 0:
        return None
    raise OSError(ctypes.get_errno(), "the kernel refuses the seccomp filter")


def _fprog(arch: str, deny: int):
    """struct sock_fprog of the program (the instructions kept alive by the buffer's ``_code``)."""
    code = _program(arch, deny, os.getpid())
    buf = ctypes.create_string_buffer(code, len(code))
    prog = ctypes.create_string_buffer(struct.pack("HxxxxxxP", len(code) // 8, ctypes.addressof(buf)), 16)
    prog._code = buf
    return prog


def answer(fd: int) -> str | None:
    """Answer the pending notification of the listener ``fd`` with EPERM; the name of the
    denied system call (None if there was none: the process went away)."""
    libc = _libc()
    req, resp = ctypes.create_string_buffer(80), ctypes.create_string_buffer(24)
    if libc.ioctl(fd, _NOTIF_RECV, req) != 0:
        return None
    ident, _, _, nr = struct.unpack_from("=QIIi", req.raw)
    struct.pack_into("=QqiI", resp, 0, ident, 0, -errno.EPERM, 0)
    libc.ioctl(fd, _NOTIF_SEND, resp)
    return next((k for k, v in _NR[machine()].items() if v == nr), str(nr))
