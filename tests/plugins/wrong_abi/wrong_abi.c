/* Test plugin: a well-formed description that claims a future ABI major version. The
 * loader must refuse it before reading anything past the version fields. */
#include <mneedle/plugin.h>

static const mneedle_plugin kPlugin = {MNEEDLE_PLUGIN_ABI_MAJOR + 1, 0, "test.wrong_abi", NULL, 0};

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
