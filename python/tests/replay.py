"""An external ego (``tadslc run --ego external:...``) that answers a recorded list of
actions, one per observation line: ``python3 replay.py actions.json``."""

import json
import sys

actions = json.load(open(sys.argv[1]))
for k, line in enumerate(sys.stdin):
    json.loads(line)
    print(json.dumps(actions[min(k, len(actions) - 1)]), flush=True)
