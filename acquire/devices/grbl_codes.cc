// GRBL 1.1's error and alarm codes, from github.com/gnea/grbl doc/csv/error_codes_en_US.csv and
// alarm_codes_en_US.csv: the short name, then the description shortened.
#include <string>

#include "acquire/devices/grbl_stage.h"

namespace lumislab {

std::string GrblErrorText(int code) {
  switch (code) {
    case 1:
      return "expected command letter (a G-code word has no letter)";
    case 2:
      return "bad number format (a word's value is missing or not a number)";
    case 3:
      return "invalid statement (a '$' command GRBL does not know)";
    case 4:
      return "value < 0 (a negative value where a positive one is expected)";
    case 5:
      return "setting disabled (homing is not enabled in the settings, $22)";
    case 6:
      return "value < 3 usec (the step pulse time must be at least 3 usec)";
    case 7:
      return "EEPROM read fail (settings restored to their defaults)";
    case 8:
      return "not idle (a '$' command that needs the Idle state)";
    case 9:
      return "G-code lock (G-code is locked out in the alarm or jog state)";
    case 10:
      return "homing not enabled (soft limits need homing)";
    case 11:
      return "line overflow (the line is too long and was not executed)";
    case 12:
      return "step rate > 30kHz (a setting exceeds the maximum step rate)";
    case 13:
      return "check door (the safety door is open)";
    case 14:
      return "line length exceeded (a startup line too long to store)";
    case 15:
      return "travel exceeded (the jog target exceeds the machine travel)";
    case 16:
      return "invalid jog command (no '=' or a prohibited G-code)";
    case 17:
      return "setting disabled (laser mode needs PWM output)";
    case 20:
      return "unsupported command (an unsupported or invalid G-code in the block)";
    case 21:
      return "modal group violation (two G-codes of one modal group in the block)";
    case 22:
      return "undefined feed rate (no feed rate set)";
    case 23:
      return "a G-code in the block requires an integer value";
    case 24:
      return "more than one G-code in the block requires axis words";
    case 25:
      return "a G-code word is repeated in the block";
    case 26:
      return "no axis words in the block for a command that requires them";
    case 27:
      return "line number value is invalid";
    case 28:
      return "a G-code is missing a required value word";
    case 29:
      return "G59.x work coordinate systems are not supported";
    case 30:
      return "G53 is only allowed with G0 and G1";
    case 31:
      return "axis words in a block with no command that uses them";
    case 32:
      return "G2 and G3 arcs require at least one in-plane axis word";
    case 33:
      return "motion command target is invalid";
    case 34:
      return "arc radius value is invalid";
    case 35:
      return "G2 and G3 arcs require at least one in-plane offset word";
    case 36:
      return "unused value words in the block";
    case 37:
      return "G43.1 offset on an axis other than the tool length axis";
    case 38:
      return "tool number greater than the maximum";
    default:
      return "unknown code";
  }
}

std::string GrblAlarmText(int code) {
  switch (code) {
    case 1:
      return "hard limit (a limit switch triggered; position lost, home again)";
    case 2:
      return "soft limit (motion target exceeds machine travel)";
    case 3:
      return "abort during cycle (reset while in motion; position lost, home again)";
    case 4:
      return "probe fail (the probe is not in the expected initial state)";
    case 5:
      return "probe fail (the probe did not contact within the travel)";
    case 6:
      return "homing fail (the homing cycle was reset)";
    case 7:
      return "homing fail (the safety door opened during homing)";
    case 8:
      return "homing fail (pull-off did not clear the limit switch)";
    case 9:
      return "homing fail (no limit switch found within the search distance)";
    case 10:
      return "homing fail (the second switch of a dual axis did not trigger)";
    default:
      return "unknown code";
  }
}

}  // namespace lumislab
