/*
 * press_c: a device driver in C on hapticsim's C API. At 1 kHz (absolute-time sleeps) it holds
 * the tool 2 mm above the default scene's contact node for 0.4 s, presses 1 cm in and back out
 * over 1.6 s, reads the force every period, and prints what the daemon answered.
 *
 *   press_c [--socket PATH]     (default: HAPTICSIM_DEFAULT_SOCKET)
 *
 * Exit status: 0 when at least 90 % of the periods were answered live and the press was felt
 * (over 0.5 N); 1 when not; 2 when it could not connect.
 */
#define _POSIX_C_SOURCE 200809L
#include <hapticsim_client.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static const double kPi = 3.14159265358979323846;

static int64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void sleep_until(int64_t at_ns) {
  struct timespec at = {(time_t)(at_ns / 1000000000), (long)(at_ns % 1000000000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, NULL) != 0) {
  }
}

int main(int argc, char** argv) {
  const char* socket_path = NULL;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--socket") == 0 && i + 1 < argc) {
      socket_path = argv[++i];
    } else {
      fprintf(stderr, "usage: press_c [--socket PATH]\n");
      return 2;
    }
  }
  char why[512];
  hapticsim_client* client = hapticsim_connect(socket_path, why, sizeof why);
  if (client == NULL) {
    fprintf(stderr, "press_c: %s\n", why); /* says what to fix */
    return 2;
  }
  /* The default scene: a 0.25 m cube pressed at the middle of its z = 0 face, along +z. */
  const double edge_m = 0.25, depth_m = 0.01;
  const int periods = 2000;
  int answered = 0, live = 0, in_contact = 0;
  double peak_n = 0, worst_error_percent = -1;
  const int64_t start = now_ns() + 1000000;
  for (int seq = 1; seq <= periods; ++seq) {
    const int64_t release = start + (int64_t)(seq - 1) * 1000000;
    sleep_until(release);
    const double t = (double)seq / periods;
    const double z = t < 0.2 ? -0.002 : depth_m * 0.5 * (1 - cos(2 * kPi * (t - 0.2) / 0.8));
    const double position_m[3] = {edge_m / 2, edge_m / 2, z};
    hapticsim_send_pose(client, seq, release / 1000, position_m);
    sleep_until(release + 900000); /* read just before the next period */
    hapticsim_force force;
    if (!hapticsim_is_live(client, now_ns())) continue; /* a real driver renders zero here */
    ++live;
    if (hapticsim_read_force(client, &force) != 1 || force.seq < 0) continue;
    ++answered;
    if (force.flags & HAPTICSIM_FLAG_IN_CONTACT) ++in_contact;
    const double magnitude =
        sqrt(force.force_n[0] * force.force_n[0] + force.force_n[1] * force.force_n[1] +
             force.force_n[2] * force.force_n[2]);
    if (magnitude > peak_n) peak_n = magnitude;
    if (force.error_percent > worst_error_percent) worst_error_percent = force.error_percent;
  }
  hapticsim_status status;
  hapticsim_read_status(client, &status);
  printf(
      "press_c: hapticsim_client %s, daemon pid %lld; %d periods: %d live, %d answered, "
      "%d in contact; peak force %.3f N; worst looked-up error %.2f %% (-1: no map)\n",
      hapticsim_client_version(), (long long)status.daemon_pid, periods, live, answered, in_contact,
      peak_n, worst_error_percent);
  hapticsim_disconnect(client);
  return answered >= periods * 9 / 10 && in_contact > 0 && peak_n > 0.5 ? 0 : 1;
}
