"""Files the tests of robotcell.programs share: the example cell and seam, RoboDK's programs."""

from pathlib import Path

TESTS = Path(__file__).resolve().parent
EXAMPLES = TESTS.parent / "examples"
#: The example cell: a KR 16 on a track beside a turntable with the frame 'part' on it.
CELL = EXAMPLES / "cell_kr16_track_turntable.yaml"
#: A seam in the frame 'part', with the table angle of each point.
SEAM = EXAMPLES / "seam_part.csv"
#: RoboDK's example station in the four formats, and cells for them (see the folder's README).
ROBODK = TESTS / "data" / "programs" / "robodk"
#: The main file of a program per format.
EXT = {"kuka": ".src", "abb": ".mod", "fanuc": ".ls", "yaskawa": ".jbi"}
