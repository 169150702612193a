#!/usr/bin/env python3
"""examples/palpation/stroke_daemon.py as a new user runs it: the phantom made, hapticsimd serving
it (at 5 mm voxels) with a tool that slides (contact.model = "proxy"), and the simulated device
stroking 60 mm across its front face over shared memory, in real time. The stiffer inclusion must
show as a bump in the force the device received; the regions must have followed the proxy across
the face; every answer must carry the error its map gives (made first over stroke_map.toml), within
the 2 % target the script asks for, or a flag saying why not (at most 5 % of them), and the
supervisor must run the dearer configurations the map asks for over the inclusion's far edge, which
the control never needs; the lateral force must stay within the static friction's cone; and the
force must not step by more than 0.12 N between answers. The largest step left is the friction's
own: the lateral force falling from μ_s to μ_k times the normal as the proxy slips, 0.1 × up to
0.77 N (measured 0.055–0.084 N quiet, 0.061–0.085 N beside two busy threads, 16 runs). Before the
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
    # The supervisor judges a sliding tool's configuration over the nodes within two of the
    # contact node (LookaheadNodes) and chooses again before the regions get to where the map
    # says it misses the target: every error the answers carried is within the script's 2 %.
    # (Judged at the node under the tool alone, the daemon ran into configurations the map calls
    # diverged a node on, and reported up to 2.43 % with 6 % of the answers' errors unknown, with
    # a map swept in the threads' order.)
    if not summary["error_percent_reported"] or \
            not 0 <= summary["error_percent_reported"][1] <= 2.0:
        wrong.append("the error reported reached %s %%, above the script's 2 %% target"
                     % (summary["error_percent_reported"] or [None, None])[1])
    # The lookup follows the material under the regions: the map says a primary of 4 with the
    # secondary at 600 or 800 Hz is 2.8–4.4 % off pressed at some of nodes 10–14 (over the
    # inclusion's far edge and past it), above the 2 % the script asks of the daemon, against
    # 0.2–0.6 % at 1000 Hz or with a primary of 5: so over the inclusion the daemon must run one of
    # these dearer ones, which the control never needs. Which of them, and whether from the start
    # (chosen at the middle node, x = 8, two nodes from the far edge) or switched to on the way, is
    # the sweep's measured cost, which is timing: any is right.
    dearer = [c for c in summary["configurations_run"] if c[0] == 5 or c[1] == 1000]
    if not dearer:
        wrong.append("the daemon ran %s (primary size, secondary Hz): the map asks for a primary "
                     "of 5 or the secondary at 1000 Hz over the inclusion's far edge"
                     % summary["configurations_run"])
    if summary["lost_answers"] != 0:
        wrong.append("%d answers were lost" % summary["lost_answers"])
    return wrong


def check_control(summary):
    # The control's map keeps a primary of 4 with a slower secondary within the script's 2 % along
    # the whole row, nodes ahead included (it ran at 600 Hz alone; the daemon may move between 600
    # and 800 Hz), and the dearer ones cost more: nothing there asks for them.
    run = summary["configurations_run"]
    if not run or any(size != 4 or rate >= 1000 for size, rate in run):
        return ["on the control phantom the daemon ran %s (primary size, secondary Hz): its map "
                "keeps a primary of 4 at a slower rate than 1000 Hz along the whole row" % run]
    return []


if __name__ == "__main__":
    sys.exit(check_bump(sys.argv[1], "stroke_daemon.py", check_rows, least_bump=0.25,
                        control_within=0.08, extra_args=["--hapticsimd", sys.argv[2]],
                        check_control=check_control))
