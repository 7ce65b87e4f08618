"""The researchers' room outside the admin: the staff pages, shared previews, norming pages, reports,
progress, pilots, study cloning and presets."""
