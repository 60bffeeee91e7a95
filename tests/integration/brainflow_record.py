"""Records BrainFlow's synthetic board for a few seconds into a file that BrainFlow's playback
board can play (DataFilter.write_file), for tests/integration/brainflow.test.ts.

    python brainflow_record.py OUT.csv SECONDS

Run in the sidecar's environment with native-bridges/python on PYTHONPATH (for the module's
fix of brainflow's library lookup on Python 3.11).
"""

from __future__ import annotations

import sys
import time

from mosaic_blocks.brainflow_board import library


def main() -> None:
    out, seconds = sys.argv[1], float(sys.argv[2])
    shim, params_class = library("brainflow")
    shim.BoardShim.set_log_level(6)  # off: nothing on stderr
    from brainflow.data_filter import DataFilter

    board = shim.BoardShim(int(shim.BoardIds.SYNTHETIC_BOARD), params_class())
    board.prepare_session()
    board.start_stream()
    time.sleep(seconds)
    data = board.get_board_data()
    board.stop_stream()
    board.release_session()
    DataFilter.write_file(data, out, "w")
    print(data.shape[1])


if __name__ == "__main__":
    main()
