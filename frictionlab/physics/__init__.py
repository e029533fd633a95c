"""The physics of one contact: what a friction law is and the registry of laws, scenes (body, contact
history, drive, effects), contact mechanics (Hertz, Mindlin, MDR), spin from rotation angle, and the one
result type of every solver. Imports only ``core``."""
