"""The data room: clips and their catalogue, imports and renders, norms, pool filters, exports and privacy.
Nothing here sees a request; the other rooms build on it."""
