/* The protocol's requests: one complete line in, one reply line out. */
#ifndef COMMANDS_H
#define COMMANDS_H

/* Answer the request in `line` (NUL-terminated, without its '\n'; split in place). */
void command_execute(char *line);

#endif
