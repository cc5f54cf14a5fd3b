"""The micro:bit board (boards/microbit) on qemu's model of its chip: boots
one firmware image in qemu-system-arm -M microbit and talks to it over its
serial line with plain sockets (SLCAN text, no CAN library), so that the
board's own drivers run: start-up, UART receive interrupt and transmit,
TIMER0 as the clock and the sleep alarm, the NVMC flash EEPROM.

  1. the bit-rate line ("S<n>") and then the boot-up frame;
  2. an SDO upload of 0x1000 is answered;
  3. a simulated-input line is answered (an unknown input: "error: ...");
  4. a 50 ms heartbeat keeps its period in real time (the timer runs at
     1 MHz: the median gap within 20 %, host load allowed for);
  5. "save" to 0x1010, the EEPROM pages copied out through the qemu monitor,
     a new qemu with that flash: the heartbeat time is still 50 ms.

The EEPROM pages start erased (an 8 KB file of 0xFF loaded at 0x3E000: the
model's flash is zero-filled, unlike a new chip). The heavier tests of
every product on every emulated board are the integration tests'.

Usage: microbit_boot.py QEMU IMAGE.elf   (exit status 0: passed)
"""
import os
import re
import select
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EEPROM_ADDR, EEPROM_SIZE = 0x3E000, 8192  # boards/microbit/link.ld
TIMEOUT = 5.0


class Failed(Exception):
    pass


class Image:
    """One qemu run of the image with the EEPROM pages from flash_file."""

    def __init__(self, qemu, elf, flash_file):
        self.proc = subprocess.Popen(
            [qemu, "-M", "microbit", "-display", "none", "-monitor", "stdio",
             "-serial", "tcp:127.0.0.1:0,server=on,wait=on", "-kernel", elf,
             "-device", f"loader,file={flash_file},addr={EEPROM_ADDR:#x},force-raw=on"],
            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            # qemu names the port it chose, and waits for the connection.
            line = self.first_line()
            m = re.search(r"waiting for connection on: disconnected:tcp:127\.0\.0\.1:(\d+)", line)
            if not m:
                raise Failed(f"qemu did not open its serial port: {line.strip()!r}")
            self.sock = socket.create_connection(("127.0.0.1", int(m.group(1))), timeout=TIMEOUT)
        except BaseException:
            self.proc.kill()
            self.proc.wait()
            raise
        self.buf = b""

    def first_line(self):
        """qemu's first line on its stderr; Failed when none comes within
        TIMEOUT (a qemu that hangs before it listens)."""
        deadline = time.monotonic() + TIMEOUT
        got = b""
        while b"\n" not in got:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.proc.stderr], [], [], left)[0]:
                raise Failed(f"qemu named no serial port within {TIMEOUT} s; it wrote {got!r}")
            chunk = os.read(self.proc.stderr.fileno(), 256)
            if not chunk:
                break  # ended: its words are the message
            got += chunk
        return got.decode(errors="replace")

    def line(self, deadline):
        """The next line from the image (without its CR), None at the deadline."""
        while b"\r" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self.sock.settimeout(left)
            try:
                data = self.sock.recv(4096)
            except socket.timeout:
                return None
            if not data:
                raise Failed("the serial connection closed")
            self.buf += data
        text, self.buf = self.buf.split(b"\r", 1)
        return text.decode(errors="replace")

    def expect(self, pattern, what):
        """Read lines until one matches pattern; its match object."""
        deadline = time.monotonic() + TIMEOUT
        seen = []
        while True:
            # The deadline holds while other lines keep coming (heartbeats).
            text = self.line(deadline) if time.monotonic() < deadline else None
            if text is None:
                raise Failed(f"no {what} within {TIMEOUT} s; lines seen: {seen[-10:]}")
            m = re.fullmatch(pattern, text)
            if m:
                return m
            seen.append(text)

    def send(self, text):
        self.sock.sendall(text.encode() + b"\r")

    def monitor(self, command):
        self.proc.stdin.write(command.encode() + b"\n")
        self.proc.stdin.flush()

    def stop(self):
        self.sock.close()
        if self.proc.poll() is None:
            self.proc.terminate()
        try:
            self.proc.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(timeout=TIMEOUT)
            raise Failed(f"qemu did not end within {TIMEOUT} s of SIGTERM: killed") from None


def sdo(node, cmd, index, sub, data=b"\0\0\0\0"):
    """An SDO request frame as an SLCAN line."""
    payload = bytes([cmd, index & 255, index >> 8, sub]) + data
    return f"t{0x600 + node:03X}8{payload.hex().upper()}"


def sdo_reply(node, cmd, index, sub):
    """Pattern of the SDO response line to a request (any data)."""
    return f"t{0x580 + node:03X}8{cmd:02X}{index & 255:02X}{index >> 8:02X}{sub:02X}([0-9A-F]{{8}})"


def boot(img):
    """The bit-rate line, then the boot-up frame; the node-ID."""
    img.expect(r"S[0-8]", "bit-rate line")
    return int(img.expect(r"t7([0-7][0-9A-F])100", "boot-up frame").group(1), 16)


def run(qemu, elf, tmp):
    erased = tmp / "erased.bin"
    erased.write_bytes(b"\xff" * EEPROM_SIZE)
    saved = tmp / "saved.bin"

    img = Image(qemu, elf, erased)
    try:
        node = boot(img)
        img.send(sdo(node, 0x40, 0x1000, 0))
        img.expect(sdo_reply(node, 0x43, 0x1000, 0), "SDO answer for 0x1000")
        img.send("set no-such-input=1")
        img.expect(r"error: .*", "answer to an input line")

        img.send(sdo(node, 0x2B, 0x1017, 0, (50).to_bytes(2, "little") + b"\0\0"))
        img.expect(sdo_reply(node, 0x60, 0x1017, 0), "answer to the heartbeat time")
        beats = []
        end = time.monotonic() + 3.0
        while time.monotonic() < end:
            text = img.line(end)
            if text == f"t{0x700 + node:03X}17F":
                beats.append(time.monotonic())
        # 60 due. The period is the median gap: a moment in which the host
        # starves qemu delays one beat (the producer does not catch up),
        # which moves the mean and the longest gap but not the median.
        if len(beats) < 20:
            raise Failed(f"{len(beats)} heartbeats in 3 s at 50 ms")
        gaps = sorted(b - a for a, b in zip(beats, beats[1:]))
        period = gaps[len(gaps) // 2]
        if not 0.040 <= period <= 0.060:
            raise Failed(f"heartbeat period {period * 1000:.1f} ms (median gap), set 50 ms")
        print(f"heartbeat: {len(beats)} in 3 s, median gap {period * 1000:.2f} ms")

        img.send(sdo(node, 0x23, 0x1010, 1, b"save"))
        img.expect(sdo_reply(node, 0x60, 0x1010, 1), "answer to save")
        # memsave reads through the CPU's view, where the SoC's flash is
        # (pmemsave's system memory does not hold it on this machine). The
        # file name quoted: the monitor reads "8192 /tmp/..." as a division.
        img.monitor(f'memsave {EEPROM_ADDR:#x} {EEPROM_SIZE} "{saved}"')
        img.monitor("quit")
        try:
            img.proc.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            raise Failed(f"qemu did not quit within {TIMEOUT} s of the monitor's quit") from None
    finally:
        img.stop()
    flash = saved.read_bytes()
    if len(flash) != EEPROM_SIZE or flash == erased.read_bytes():
        raise Failed("the save left the EEPROM pages erased")

    img = Image(qemu, elf, saved)
    try:
        boot(img)
        img.send(sdo(node, 0x40, 0x1017, 0))
        got = img.expect(sdo_reply(node, 0x4B, 0x1017, 0), "heartbeat time after the restart")
        if got.group(1) != "32000000":
            raise Failed(f"heartbeat time after the restart: {got.group(1)}, saved 50 ms")
    finally:
        img.stop()


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        try:
            run(argv[1], argv[2], Path(tmp))
        except Failed as e:
            print(f"FAILED: {e}", file=sys.stderr)
            return 1
    print("passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
