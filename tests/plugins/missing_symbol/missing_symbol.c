/* Test plugin: a shared library that exports a function, but not mneedle_plugin_entry. */
#include <mneedle/plugin.h>

MNEEDLE_PLUGIN_EXPORT int mneedle_plugin_entry_misspelled(void) {
  return 0;
}
