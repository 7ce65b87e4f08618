"""The participant's room: the study pages a participant sees and what they need (assignment,
counterbalancing, viewing records, media streaming, the start throttle)."""
