#!/usr/bin/env python3
"""examples/palpation/stroke_daemon.py as a new user runs it: the phantom made, hapticsimd serving
it (at 5 mm voxels) with a tool that slides (contact.model = "proxy"), and the simulated device
stroking 60 mm across its front face over shared memory, in real time. The stiffer inclusion must
show as a bump in the force the device received; the regions must have followed the proxy across
the face; every answer must carry the error its map gives (made first over stroke_map.toml), within
the daemon's default 7 % target (the script asks for 2 %), or a flag saying why not (at most 5 % of
them), and the supervisor must switch to the 1000 Hz the map asks for over the inclusion's far
edge, which the control never needs; the lateral force must stay within the static friction's cone; and the force must not
step by more than 0.12 N between answers. The largest step left is the friction's own: the
lateral force falling from μ_s to μ_k times the normal as the proxy slips, 0.1 × up to 0.77 N
(measured 0.055–0.084 N quiet, 0.061–0.085 N beside two busy threads, 16 runs). Before the
proxy followed the tool through a move's pause (SlidingContact::CatchUp), a tool lifting out
during one dropped the force to nothing for a period: 0.11–0.18 N. A control phantom whose
inclusion is as soft as the tissue shows no bump beyond the block's own shape (measured: 4.3 %).

Usage: palpation_stroke_daemon_test.py HAPTICSIM HAPTICSIMD   (exit 0: passed; 1: what failed is
printed)"""
import sys

from phantom_example import check_bump


def check_rows(summary, rows):
    wrong = []
    if rows[0] != "x_mm,normal_force_N,lateral_force_N" or len(rows) < 1 + 2000:
        wrong.append("the CSV has %d rows: two strokes' slides are about 3,200 answers" % len(rows))
    if not summary["regions_moved"] >= 20:
        wrong.append("the regions moved %s times over three 60 mm strokes of 5 mm voxels"
                     % summary["regions_moved"])
    if not summary["largest_lateral_to_normal"] <= 0.5 * 1.05:
        wrong.append("the lateral force reached %.3f × the normal, above μ_s = 0.5"
                     % summary["largest_lateral_to_normal"])
    if not summary["largest_step_N"] < 0.12:
        wrong.append("the force stepped by %.3f N between answers" % summary["largest_step_N"])
    # Given the phantom's map, every answer says how wrong its force is, within the target (7 %),
    # or flags why it cannot (the supervisor choosing again where the map has none: about the
    # switch away from 600 Hz, in the first stroke, so far always before the judged ones).
    if summary["answers_error_unknown_unflagged"] != 0 or \
            summary["answers_error_unknown"] > 0.05 * summary["answers_in_slides"]:
        wrong.append("%d answers in the slides carried no error, %d of them without a flag "
                     "saying why" % (summary["answers_error_unknown"],
                                     summary["answers_error_unknown_unflagged"]))
    if not summary["error_percent_reported"] or \
            not 0 <= summary["error_percent_reported"][1] <= 7:
        wrong.append("the error reported reached %.3f %%, above the daemon's default 7 %% target"
                     % summary["error_percent_reported"][1])
    # The lookup follows the material under the regions: the map says a primary of 4 or 5 with the
    # secondary at 600 or 800 Hz is 2.8–4.4 % off pressed at some of nodes 10–14 (over the
    # inclusion's far edge and past it), above the 2 % the script asks of the daemon, against
    # 0.2–0.6 % at 1000 Hz; so the daemon must start below 1000 Hz (in step costs a third more) and
    # switch to 1000 Hz on the way there; on the control phantom it has no reason to switch.
    # (Until the port limits acted on the displacement exchange at another rate, 2026-12-07, those
    # slower configurations diverged there.) Whether it starts at 600 or 800 Hz is the sweep's
    # measured cost, which is timing: either is right.
    rates = summary["secondary_rates_hz_run"]
    if not (rates and rates[0] < 1000 and 1000 in rates[1:]):
        wrong.append("the secondary ran at %s Hz: the map asks it to switch to 1000 Hz before the "
                     "inclusion's far edge" % rates)
    if summary["lost_answers"] != 0:
        wrong.append("%d answers were lost" % summary["lost_answers"])
    return wrong


def check_control(summary):
    # The control's map keeps a slower rate within the script's 2 % along the whole row (it ran at
    # 600 Hz alone; the daemon may move between 600 and 800 Hz), and 1000 Hz costs more: nothing
    # there asks for it.
    if not summary["secondary_rates_hz_run"] or 1000 in summary["secondary_rates_hz_run"]:
        return ["on the control phantom the secondary ran at %s Hz: its map keeps a cheaper rate "
                "than 1000 Hz along the whole row" % summary["secondary_rates_hz_run"]]
    return []


if __name__ == "__main__":
    sys.exit(check_bump(sys.argv[1], "stroke_daemon.py", check_rows, least_bump=0.25,
                        control_within=0.08, extra_args=["--hapticsimd", sys.argv[2]],
                        check_control=check_control))
