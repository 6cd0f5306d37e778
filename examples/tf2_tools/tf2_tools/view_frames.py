"""view_frames: listen to /tf and /tf_static for 5 s, write the tree to frames.gv and frames.pdf.

As the tutorial types it: `rosl run tf2_tools view_frames && evince frames.pdf`.
The PDF is drawn by Graphviz when it is installed, otherwise by rosl itself.
"""

import sys
from pathlib import Path

from rosl.errors import RoslError
from rosl.introspection import tf
from rosl.introspection.session import Session

WAIT_S = 5.0


def main(args=None):
    del args
    print(f"[INFO] [view_frames]: Listening to tf data for {WAIT_S} seconds...", flush=True)
    try:
        with Session() as session:
            buffer = tf.frames(session, WAIT_S)
        Path("frames.gv").write_text(tf.frames_dot(buffer), encoding="utf-8")
        print("[INFO] [view_frames]: Generating graph in frames.pdf file...", flush=True)
        tf.export(buffer, Path("frames.pdf"))
    except RoslError as err:
        print(f"view_frames: {err}", file=sys.stderr, flush=True)
        return 1
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
