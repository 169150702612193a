/*
 * The C side of the cross-language check of the LCM types (python_types_test.py):
 *   c_codec encode-status        a status_t with two regions, encoded, as hex on stdout
 *   c_codec decode-force HEX     a force_feedback_t decoded, its fields on stdout
 */
#include <hapticsim_force_feedback_t.h>
#include <hapticsim_status_t.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int encode_status(void) {
  hapticsim_region_status_t regions[2];
  memset(regions, 0, sizeof regions);
  regions[0].name = (char*)"primary";
  regions[0].nodes = 125;
  regions[0].rate_hz = 1000.0;
  regions[0].cycles = 123456789012LL;
  regions[0].execution_p99_us = 41.5;
  regions[1].name = (char*)"secondary";
  regions[1].nodes = 2197;
  regions[1].rate_hz = 600.0;
  regions[1].deadline_misses = -3;
  hapticsim_status_t s;
  memset(&s, 0, sizeof s);
  s.utime = 1700000000123456LL;
  s.primary_size = 3;
  s.secondary_lod = 2;
  s.secondary_rate_hz = 600.0;
  s.error_percent = 4.25;
  s.target_met = 1;
  s.error_map = (char*)"/var/lib/hapticsim/liver.hsmap";
  s.contact_node[0] = 6;
  s.contact_node[1] = 6;
  s.contact_node[2] = 0;
  s.input_owner = (char*)"shm";
  s.stalled_threads = (char*)"";
  s.port_energy_dissipated_j = 1.5e-5;
  s.num_regions = 2;
  s.regions = regions;
  const int size = hapticsim_status_t_encoded_size(&s);
  unsigned char* buffer = malloc((size_t)size);
  if (hapticsim_status_t_encode(buffer, 0, size, &s) != size) return 1;
  for (int i = 0; i < size; ++i) printf("%02x", buffer[i]);
  printf("\n");
  free(buffer);
  return 0;
}

static int decode_force(const char* hex) {
  const size_t size = strlen(hex) / 2;
  unsigned char* buffer = malloc(size);
  for (size_t i = 0; i < size; ++i) {
    unsigned int byte;
    if (sscanf(hex + 2 * i, "%2x", &byte) != 1) return 1;
    buffer[i] = (unsigned char)byte;
  }
  hapticsim_force_feedback_t f;
  if (hapticsim_force_feedback_t_decode(buffer, 0, (int)size, &f) < 0) return 1;
  printf("utime %lld period %lld seq %lld first_seq %lld force %.17g %.17g %.17g error %.17g "
         "flags %d\n",
         (long long)f.utime, (long long)f.period, (long long)f.seq, (long long)f.first_seq,
         f.force[0], f.force[1], f.force[2], f.error_percent, f.flags);
  hapticsim_force_feedback_t_decode_cleanup(&f);
  free(buffer);
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "encode-status") == 0) return encode_status();
  if (argc == 3 && strcmp(argv[1], "decode-force") == 0) return decode_force(argv[2]);
  fprintf(stderr, "usage: c_codec encode-status | decode-force HEX\n");
  return 2;
}
