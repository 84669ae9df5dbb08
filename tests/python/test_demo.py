"""The README's demo runs end to end (quick mode) and shows what it claims."""
import re
import subprocess
import sys


def test_demo_quick_runs_the_whole_bench():
    out = subprocess.run([sys.executable, "-m", "motorbus", "demo", "--quick"], capture_output=True, text=True,
                         timeout=180)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "@01 X2000 -> EX=2000 PX=2000" in text
    assert "@02 X-1000 -> EX=-1000" in text
    assert "DMAC 00 MOVE_TO 5000 -> #POSITION=5000" in text
    assert re.search(r"python-can socketcand -> python-can slcan: 5/5 frames", text)
    assert "recorded 100 frames" in text and "read back 100 frames (0 bad lines)" in text
    assert "device type 0x00040192, name 'PMC007 (simulated)', vendor 0xAB" in text
    assert "baud index 9 refused: abort 0x06090031" in text
    assert "block transfer of 4096 bytes down and up" in text and "identical: True" in text
    assert "loaded it back: 0x1008 = 'PMC007 (simulated)'" in text
    assert text.rstrip().endswith("demo finished")
