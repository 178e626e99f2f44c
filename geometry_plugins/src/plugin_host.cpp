// placeholder: the plugin loader is being written (issue 2 §4)
