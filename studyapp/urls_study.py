"""Routes of the study app (namespace "studyapp"): participant pages under /s/<slug>/ (entry) and /p/<token>/,
clip media under /m/, researcher pages (staff only) under /staff/."""
from django.urls import path

from .participant import views, views_pages
from .staff import views as views_staff
from .staff import views_norming, views_share

app_name = "studyapp"

urlpatterns = [
    path("", views.home, name="home"),
    path("s/<slug:slug>/", views.study_entry, name="study_entry"),
    path("p/<str:token>/", views.resume, name="resume"),
    path("p/<str:token>/about-you/", views.demographics, name="demographics"),
    path("p/<str:token>/clip/<int:n>/", views.item, name="item"),
    path("p/<str:token>/clip/<int:n>/playback", views.playback, name="playback"),
    path("p/<str:token>/page/<int:n>/", views_pages.page, name="page"),
    path("p/<str:token>/feedback/", views.feedback, name="feedback"),
    path("p/<str:token>/done/", views.done, name="done"),
    path("m/<str:key>.<str:ext>", views.media, name="media"),
    path("preview/<str:token>/", views_share.shared_preview, name="shared_preview"),
    path("preview/<str:token>/<int:n>/", views_share.shared_preview_item, name="shared_preview_item"),
    path("staff/new-from-preset/", views_staff.create_from_preset, name="create_from_preset"),
    path("staff/study/<int:study_id>/preview/", views_staff.preview_start, name="preview_start"),
    path("staff/study/<int:study_id>/preview/<int:n>/", views_staff.preview_item, name="preview_item"),
    path("staff/study/<int:study_id>/progress/", views_staff.progress, name="progress"),
    path("staff/study/<int:study_id>/clone/", views_staff.clone, name="clone_study"),
    path("staff/study/<int:study_id>/pilot/delete/", views_staff.delete_pilot, name="delete_pilot"),
    path("staff/study/<int:study_id>/share/", views_staff.share_preview, name="share_preview"),
    path("staff/study/<int:study_id>/norming/", views_norming.norming_monitor, name="norming_monitor"),
    path("staff/study/<int:study_id>/export/<str:kind>.csv", views_staff.export_csv, name="export_csv"),
    path("staff/study/<int:study_id>/data.zip", views_staff.data_zip, name="data_zip"),
    path("staff/study/<int:study_id>/report.zip", views_staff.report_zip, name="report_zip"),
    path("staff/study/<int:study_id>/payment-ids.csv", views_staff.payment_ids, name="payment_ids"),
]
