#!/usr/bin/env bash
# Writes the seed corpora for the fuzz targets from the docs/protocols.md golden vectors, typed
# in hex by hand. Idempotent: run it again after editing a vector.
#   fuzz/corpus/fuzz_framer/    3-byte prefix (families, servo count, max chunk) + byte stream
#   fuzz/corpus/fuzz_decoders/  1-byte selector (decoder + 5 * mode), servo count, frame
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${1:-$here/corpus}"
mkdir -p "$out/fuzz_framer" "$out/fuzz_decoders"

# write FILE HEX...: the hex bytes (spaces allowed) as a binary file.
write() {
  local file="$1" hex
  shift
  hex="$(echo "$*" | tr -d ' \t\n')"
  if [[ ! "$hex" =~ ^([0-9A-Fa-f]{2})+$ ]]; then
    echo "bad hex for $file" >&2
    exit 1
  fi
  printf '%b' "$(echo "$hex" | sed -E 's/(..)/\\x\1/g')" > "$file"
}

# --- golden frames (docs/protocols.md) ------------------------------------------------------------
base_reset="55 AA 02 02 05 00 FA"
base_battery_request="55 AA 02 01 02 00 FE"
base_clear_encoders="55 AA 02 03 06 00 F8"
base_left4="55 AA 09 00 01 00 04 00 00 00 00 00 00 F3"
base_both_minus6="55 AA 09 00 01 FF FA FF FA 00 00 00 00 F7"
base_battery_reply="55 AA 02 07 02 64 9C"
base_error_status="55 AA 02 08 FF 00 0A"
telemetry="12 34 20 08 00 00 0A 04 00 FF FB 00 01 FF FF 40 00 00 00 00 00 00 64 00 00 00 00 C0 00 93 1F 2F"
telemetry_foot="12 34 30 08 00 00 0A 04 00 FF FB 00 01 FF FF 40 00 00 00 00 00 00 64 00 00 00 00 C0 00
                01 00 02 00 03 00 04 00 05 00 06 00 07 00 08 00 C7 1F 2F"
sync_write="FF FF FD 00 FE 0D 00 83 74 00 02 00 02 00 08 03 00 04 79 68"
dynamixel_ping="FF FF FD 00 01 03 00 01 19 4E"
servo_ping="12 4C 01 01 03 63"
servo_rotate="12 4C 08 07 02 84 03 F4 01 00 00 EB"
servo_read_angle="12 4C 0A 01 00 69"
servo_spin_ms="12 4C 07 06 00 83 64 00 E8 03 3D"
servo_damping="12 4C 09 03 00 F4 01 5F"
servo_ping_reply="05 1C 01 01 03 26"
servo_read_angle_reply="05 1C 0A 03 00 86 03 B7"

# --- fuzz_framer: prefix = families (1F all), servo count (02), max chunk (00 = one feed) -------
f="$out/fuzz_framer"
write "$f/base_reset" "1F 02 00 $base_reset"
write "$f/base_wheels" "1F 02 00 $base_left4 $base_both_minus6"
write "$f/base_replies" "01 00 00 $base_battery_reply $base_error_status"
write "$f/telemetry" "1F 02 00 $telemetry"
write "$f/telemetry_foot_chunked" "02 02 05 $telemetry_foot $telemetry"
write "$f/sync_write" "1F 02 00 $sync_write"
write "$f/simulator_input" "19 00 04 $dynamixel_ping $sync_write $servo_rotate $base_reset"
write "$f/servo_requests" "1F 02 00 $servo_ping $servo_rotate $servo_read_angle $servo_spin_ms $servo_damping"
write "$f/servo_responses" "0C 02 01 $servo_ping_reply $servo_read_angle_reply"
write "$f/driver_mixed_with_junk" "0F 02 07 00 55 12 $telemetry 05 $base_battery_reply FF FF
  $servo_read_angle $servo_read_angle_reply 12 34 $telemetry_foot $base_error_status"
write "$f/everything_reset" "9F 02 03 $telemetry $sync_write $base_clear_encoders $servo_ping_reply
  $base_battery_request $telemetry_foot"

# --- fuzz_decoders: selector = decoder (0 base .. 4 sync write) + 5 * mode, then servo count ----
d="$out/fuzz_decoders"
write "$d/base_raw" "00 02 $base_reset"
write "$d/base_wheels_raw" "00 02 $base_both_minus6"
write "$d/base_battery_fixsum" "05 02 $base_battery_reply"
write "$d/base_fixall" "0A 02 $base_left4"
write "$d/telemetry_raw" "01 02 $telemetry"
write "$d/telemetry_foot_raw" "01 02 $telemetry_foot"
write "$d/telemetry_fixsum" "06 02 $telemetry"
write "$d/telemetry_fixall" "0B 06 $telemetry_foot"
write "$d/servo_response_raw" "02 00 $servo_read_angle_reply"
write "$d/servo_response_fixsum" "07 00 $servo_ping_reply"
write "$d/servo_read_data_fixall" "0C 00 05 1C 03 04 03 01 E8 2E 00"
write "$d/servo_read_batch_fixall" "0C 00 05 1C 05 21 01 00 01 01 00 05 01 88 13 40 1F 80 3E
  50 00 B8 0B E8 03 01 00 00 00 00 01 F4 01 84 03 7C FC 00 00 00"
write "$d/servo_request_raw" "03 00 $servo_rotate"
write "$d/servo_request_fixsum" "08 00 $servo_spin_ms"
# One seed per move of the command table (CMD 11..16), so each typed request is reached at once.
write "$d/servo_move_by_interval_raw" "03 00 12 4C 0B 0B 01 84 03 E8 03 64 00 64 00 00 00 AF"
write "$d/servo_move_by_velocity_raw" "03 00 12 4C 0C 0B 01 7C FC 10 0E 64 00 64 00 00 00 D4"
write "$d/servo_multi_turn_move_raw" "03 00 12 4C 0D 0B 01 20 1C 00 00 D0 07 00 00 00 00 8A"
write "$d/servo_multi_turn_by_interval_raw" "03 00 12 4C 0E 0F 01 F0 F1 FF FF E8 03 00 00 C8 00 C8
  00 00 00 D6"
write "$d/servo_multi_turn_by_velocity_raw" "03 00 12 4C 0F 0D 01 A0 8C 00 00 10 0E 64 00 64 00 00
  00 8D"
write "$d/servo_read_multi_turn_reply_raw" "02 00 05 1C 10 07 01 20 1C 00 00 02 00 77"
write "$d/sync_write_raw" "04 00 $sync_write"
write "$d/sync_write_fixcrc" "09 00 $sync_write"
write "$d/sync_write_fixall" "0E 00 $sync_write 05 00 08"
write "$d/dynamixel_ping_raw" "04 00 $dynamixel_ping"

echo "corpus written to $out ($(ls "$out/fuzz_framer" | wc -l) framer seeds," \
     "$(ls "$out/fuzz_decoders" | wc -l) decoder seeds)"
